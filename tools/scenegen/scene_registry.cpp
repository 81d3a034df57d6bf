// The table of bundled scenes (see scene_registry.h). Adding a scene is one builder file and
// one line here.
#include "tools/scenegen/scene_registry.h"

#include "common/util/error.h"

namespace pr::scenegen {

namespace {
constexpr SceneProperties kStress{"sphere segments around (rings = half)", 24, 8, 128, false, 0};
}

const SceneRegistry& sceneRegistry() {
  static const SceneRegistry kScenes(
      "scene",
      {
          {"cornell", "Cornell box with a glass and a mirror sphere under a ceiling area light (Jensen 1996, fig. 6)",
           buildCornell, {"sphere segments around (rings = half)", 64, 8, 256, false, 0}},
          {"cornell-diffuse", "the same box, camera and light with both spheres white diffuse", buildCornellDiffuse,
           {"sphere segments around (rings = half)", 64, 8, 256, false, 0}},
          {"cornell-glass", "the same box with the glass sphere and a white diffuse one (the photon map's accuracy benchmark)",
           buildCornellGlass, {"sphere segments around (rings = half)", 64, 8, 256, false, 0}},
          {"cornell-rough", "the same box with a rough metal block and a frosted, partly transmissive sphere (glossy light)",
           buildCornellRough, {"sphere segments around (rings = half)", 64, 8, 256, false, 0}},
          {"landscape", "fBm Perlin terrain lit by a spherical light directly and through a glass lens (Jensen 1996, fig. 4)",
           buildLandscape, {"terrain grid cells per side (2 * size^2 triangles)", 708, 1, 2048, true, 1}},
          {"hotspot", "load-balancing study: a dense cluster of spheres in the top-left corner of a plain room",
           buildHotspot, {"segments around each sphere (rings = half)", 48, 8, 256, true, 1}},
          // Hard cases for the numerics (stress.cpp); behaviour documented in scenes/README.md.
          {"stress-scale-small", "the stress stage (floor, wall, sphere, point light) at scale 1e-6", buildStressScaleSmall, kStress},
          {"stress-scale-large", "the same stage at scale 1e6", buildStressScaleLarge, kStress},
          {"stress-degenerate", "the stage with a grid whose triangles are half degenerate (a repeated vertex, three collinear)", buildStressDegenerate, kStress},
          {"stress-zfight", "two coincident quads of different colours (z-fighting) and one 1e-7 in front", buildStressZFight, kStress},
          {"stress-camera-inside", "the camera inside a closed double-sided sphere lit from inside", buildStressCameraInside, kStress},
          {"stress-light-inside", "the only light inside a closed box", buildStressLightInside, kStress},
          {"stress-light-on-surface", "the only light exactly on the floor", buildStressLightOnSurface, kStress},
          {"stress-thin-glass", "a glass slab 0.1 thick with attenuation distance 1e-3 (transmittance colour^100)", buildStressThinGlass, kStress},
          {"stress-dielectrics", "nested (water in glass) and touching (two glass cubes) dielectrics", buildStressDielectrics, kStress},
          {"stress-fireflies", "the only light a 1 cm square of radiance 1e6", buildStressFireflies, kStress},
          {"stress-huge-triangle", "one ground triangle about 1e7 pixels across", buildStressHugeTriangle, kStress},
          {"stress-total-reflection", "the camera inside a cube of ior 2.4: total internal reflection to the depth limit", buildStressTotalReflection, kStress},
      });
  return kScenes;
}

const SceneEntry& findScene(std::string_view name) { return sceneRegistry().find(name); }

GltfBuilder generateScene(const SceneEntry& entry, const SceneParams& params) {
  const SceneProperties& scene = entry.properties;
  if (params.size < scene.minSize || params.size > scene.maxSize)
    throw InputError("--size " + std::to_string(params.size) + " is out of range for scene '" + entry.name +
                     "' (" + std::string(scene.sizeMeaning) + ": " + std::to_string(scene.minSize) + " to " +
                     std::to_string(scene.maxSize) + ")");
  std::string generator = "parrender generate " + entry.name + " --size " + std::to_string(params.size);
  if (scene.usesSeed) generator += " --seed " + std::to_string(params.seed);
  GltfBuilder builder(generator);
  entry.make(builder, params);
  return builder;
}

}  // namespace pr::scenegen
