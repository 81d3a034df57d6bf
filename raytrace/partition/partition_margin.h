// The margin by which the partitioned tracers grow a partition's region before deciding what
// it holds (object-space voxels) or whether a ray can reach it (object bounds in object
// partitioning). Hit distances and region boundaries are computed in float: the margin makes
// both decisions conservative, so a partitioned tracer finds exactly the hits of the full BVH.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/glm.hpp>

#include "common/scene/scene.h"

namespace pr::rt {

// 2^-12 = 4096 ulps of the largest coordinate a ray can start from (any vertex of the scene,
// or the eye). Hit distances (the plane equation of triangle.h) and span boundaries (one
// division per kd node, one slab test per box) each err by a few ulps of the distance
// travelled, which stays below that coordinate plus the scene's size: 4096 ulps leave a wide
// safety factor and still duplicate few triangles. Grazing hits, whose distance is
// ill-conditioned, are the exception no margin can cover.
inline constexpr float kPartitionMarginFraction = 0x1p-12f;

inline float partitionMargin(const scene::Scene& s, glm::vec3 eye) {
  const auto maxAbs = [](glm::vec3 v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); };
  float magnitude = std::isfinite(maxAbs(eye)) ? maxAbs(eye) : 0.0f;
  for (const scene::Triangle& t : s.triangles)
    for (uint32_t v : t.v)
      if (const float m = maxAbs(s.positions[v]); std::isfinite(m)) magnitude = std::max(magnitude, m);
  // A scene collapsed onto the origin still gets a positive margin.
  return std::max(kPartitionMarginFraction * magnitude, std::numeric_limits<float>::min());
}

}  // namespace pr::rt
