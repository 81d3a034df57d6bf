// The any-hit test of alpha-cut surfaces (alphaMode MASK and BLEND): a triangle hit counts only
// where the material's opacity lets the surface be there (scene::alphaPasses) - closest-hit
// and shadow queries alike, so a cut-out leaf casts a leaf-shaped shadow. BLEND is stochastic
// transparency: the decision's random number is a hash of the ray and the triangle, so a ray
// sees the same surfaces in every tracer and on every PE. Built once per scene, read by every
// BVH traversal that holds it (BvhBuildOptions::alpha).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"

namespace pr::rt {

class AlphaTest {
 public:
  explicit AlphaTest(const scene::Scene& scene);
  // The test for this scene, or null when no material can cut (no test to run).
  static std::shared_ptr<const AlphaTest> forScene(const scene::Scene& scene);

  // Whether the surface is there at the hit (u, v) of scene triangle `triangle` by `ray`.
  bool passes(uint32_t triangle, float u, float v, const Ray& ray) const;

 private:
  const scene::Scene* scene_;
  std::vector<uint8_t> cuts_;  // per scene triangle: its material can cut
};

}  // namespace pr::rt
