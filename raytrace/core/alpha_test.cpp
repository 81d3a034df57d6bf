// Alpha-cut any-hit test (see alpha_test.h).
#include "raytrace/core/alpha_test.h"

#include <bit>

#include "common/scene/surface_material.h"
#include "common/util/hash.h"

namespace pr::rt {

AlphaTest::AlphaTest(const scene::Scene& scene) : scene_(&scene), cuts_(scene.triangles.size(), 0) {
  for (size_t t = 0; t < scene.triangles.size(); ++t)
    cuts_[t] = scene::alphaCuts(scene.materials[scene.triangles[t].material]) ? 1 : 0;
}

std::shared_ptr<const AlphaTest> AlphaTest::forScene(const scene::Scene& scene) {
  for (const scene::Triangle& t : scene.triangles)
    if (scene::alphaCuts(scene.materials[t.material])) return std::make_shared<const AlphaTest>(scene);
  return nullptr;
}

bool AlphaTest::passes(uint32_t triangle, float u, float v, const Ray& ray) const {
  if (triangle >= cuts_.size() || !cuts_[triangle]) return true;
  const scene::Scene& s = *scene_;
  const scene::Triangle& tri = s.triangles[triangle];
  const float b0 = 1.0f - u - v;
  glm::vec2 uv(0.0f);
  if (s.uvs.size() == s.positions.size()) uv = b0 * s.uvs[tri.v[0]] + u * s.uvs[tri.v[1]] + v * s.uvs[tri.v[2]];
  glm::vec4 colour(1.0f);
  if (s.colors.size() == s.positions.size())
    colour = b0 * s.colors[tri.v[0]] + u * s.colors[tri.v[1]] + v * s.colors[tri.v[2]];
  const scene::Material& m = s.materials[tri.material];
  const float opacity = scene::opacityAt(s, tri.material, uv, colour);
  if (m.alphaMode != scene::AlphaMode::Blend) return scene::alphaPasses(m, opacity, 0.0f);
  // The ray's bits and the triangle decide: the same ray meets the same surfaces everywhere.
  uint64_t h = mix64(0x0a1fa0b1e4d5eedull ^ triangle);
  for (float f : {ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, ray.direction.y, ray.direction.z})
    h = mix64(h ^ std::bit_cast<uint32_t>(f));
  return scene::alphaPasses(m, opacity, unitFloat(h));
}

}  // namespace pr::rt
