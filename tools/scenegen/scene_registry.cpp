// The table of bundled scenes (see scene_registry.h). Adding a scene is one builder file and
// one line here.
#include "tools/scenegen/scene_registry.h"

#include "common/util/error.h"

namespace pr::scenegen {

const SceneRegistry& sceneRegistry() {
  static const SceneRegistry kScenes(
      "scene",
      {
          {"cornell", "Cornell box with a glass and a mirror sphere under a ceiling area light (Jensen 1996, fig. 6)",
           buildCornell, {"sphere segments around (rings = half)", 64, 8, 256, false, 0}},
          {"cornell-diffuse", "the same box, camera and light with both spheres white diffuse", buildCornellDiffuse,
           {"sphere segments around (rings = half)", 64, 8, 256, false, 0}},
          {"landscape", "fBm Perlin terrain lit by a spherical light directly and through a glass lens (Jensen 1996, fig. 4)",
           buildLandscape, {"terrain grid cells per side (2 * size^2 triangles)", 708, 1, 2048, true, 1}},
          {"hotspot", "load-balancing study: a dense cluster of spheres in the top-left corner of a plain room",
           buildHotspot, {"segments around each sphere (rings = half)", 48, 8, 256, true, 1}},
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
