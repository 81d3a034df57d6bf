// Scene statistics for `parrender info` and run records: counted from the render-ready arrays,
// so they describe what the renderers actually receive, not what the file declares.
#include "common/scene/scene_stats.h"

namespace pr::scene {

SceneStats computeStats(const Scene& scene) {
  SceneStats s;
  s.file = scene.source.string();
  s.triangles = scene.triangles.size();
  s.vertices = scene.positions.size();
  s.objects = scene.objects.size();
  // Materials as drawn: the glTF default material counts only when a primitive falls back to it.
  std::vector<bool> used(scene.materials.size(), false);
  for (const Triangle& t : scene.triangles) used[t.material] = true;
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    if (!used[m]) continue;
    ++s.materials;
    ++s.materialsByKind[size_t(scene.materials[m].kind())];
  }
  for (const PunctualLight& l : scene.lights) {
    switch (l.type) {
      case LightType::Point: ++s.pointLights; break;
      case LightType::Spot: ++s.spotLights; break;
      case LightType::Directional: ++s.directionalLights; break;
    }
  }
  s.areaLightTriangles = scene.areaLights.size();
  for (const AreaLight& a : scene.areaLights) s.emissiveArea += a.area;
  for (const Texture& t : scene.textures) {
    if (t.rgba8.empty()) continue;
    ++s.textures;
    s.texels += size_t(t.width) * size_t(t.height);
  }
  s.cameras = scene.cameras.size();
  s.bounds = scene.bounds;
  s.extensionsUsed = scene.extensionsUsed;
  s.warnings = scene.warnings;
  s.memoryBytes = scene.memoryBytes();
  return s;
}

}  // namespace pr::scene
