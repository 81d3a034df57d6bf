// The table of bundled scenes (see scene_registry.h). Adding a scene is one builder file and
// one line here.
#include "tools/scenegen/scene_registry.h"

#include "common/util/error.h"

namespace pr::scenegen {

const std::vector<SceneEntry>& sceneRegistry() {
  static const std::vector<SceneEntry> kScenes = {
      {"cornell", "Cornell box with a glass and a mirror sphere under a ceiling area light (Jensen 1996, fig. 6)",
       "sphere segments around (rings = half)", 64, 8, 256, false, 0, buildCornell},
      {"cornell-diffuse", "the same box, camera and light with both spheres white diffuse",
       "sphere segments around (rings = half)", 64, 8, 256, false, 0, buildCornellDiffuse},
      {"landscape", "fBm Perlin terrain lit by a spherical light directly and through a glass lens (Jensen 1996, fig. 4)",
       "terrain grid cells per side (2 * size^2 triangles)", 708, 1, 2048, true, 1, buildLandscape},
      {"hotspot", "load-balancing study: a dense cluster of spheres in the top-left corner of a plain room",
       "segments around each sphere (rings = half)", 48, 8, 256, true, 1, buildHotspot},
  };
  return kScenes;
}

const SceneEntry& findScene(std::string_view name) {
  std::string known;
  for (const auto& scene : sceneRegistry()) {
    if (scene.name == name) return scene;
    known += (known.empty() ? "" : ", ") + std::string(scene.name);
  }
  throw InputError("unknown scene '" + std::string(name) + "' (known scenes: " + known + ")");
}

GltfBuilder generateScene(const SceneEntry& scene, const SceneParams& params) {
  if (params.size < scene.minSize || params.size > scene.maxSize)
    throw InputError("--size " + std::to_string(params.size) + " is out of range for scene '" + std::string(scene.name) +
                     "' (" + std::string(scene.sizeMeaning) + ": " + std::to_string(scene.minSize) + " to " +
                     std::to_string(scene.maxSize) + ")");
  std::string generator = "parrender generate " + std::string(scene.name) + " --size " + std::to_string(params.size);
  if (scene.usesSeed) generator += " --seed " + std::to_string(params.seed);
  GltfBuilder builder(generator);
  scene.build(builder, params);
  return builder;
}

}  // namespace pr::scenegen
