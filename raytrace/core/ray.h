// Rays and hit records of the ray tracing core: what every tracer (image-space, object-space,
// object partitioning) hands to the BVH and gets back. A hit names the scene triangle, so hit
// records from different PEs' BVHs compare directly (object partitioning keeps the closest).
#pragma once

#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace pr::rt {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
inline constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();

// A ray o + t d, valid for t in the closed interval [tMin, tMax]. The direction need not be
// unit length (shadow rays towards a point use d = target - o and tMax just below 1).
struct Ray {
  glm::vec3 origin{0.0f};
  float tMin = 0.0f;
  glm::vec3 direction{0.0f, 0.0f, -1.0f};
  float tMax = kInfinity;
};

// The nearest hit of a closest-hit query. Barycentrics follow p = (1-u-v) p0 + u p1 + v p2 of
// the scene triangle's vertices v[0], v[1], v[2]. Equal t is broken towards the lower triangle
// index, so the record never depends on traversal order or on how the scene was partitioned.
struct Hit {
  float t = kInfinity;
  uint32_t triangle = kNoTriangle;
  float u = 0.0f;
  float v = 0.0f;

  bool valid() const { return triangle != kNoTriangle; }
  // The deterministic order of hit records: nearer first, then lower triangle index.
  bool closerThan(const Hit& other) const {
    return t < other.t || (t == other.t && triangle < other.triangle);
  }
};

}  // namespace pr::rt
