// Robust origins for secondary rays (shadow, reflection, refraction, bounce), after Wächter and
// Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6):
// the hit point is pushed off its triangle along the geometric normal by a number of ulps of
// each coordinate, found by integer arithmetic on the float's bits, so the offset follows the
// float exponent at every scale. Used by interaction.cpp when a tracer spawns a ray.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace pr::rt {

// The chapter's constants, for coordinates of magnitude ~1: 256 ulps of the coordinate, or a
// fixed 2^-16 below 1/32, where the ulps of small coordinates get too small to cover the error.
// That error is set by the magnitude of the triangle's vertices, not of the point itself (a
// point near 0 on an edge from -1e5 to 1e5 is as uncertain as the vertices), and it is per axis:
// p = b0 p0 + b1 p1 + b2 p2 rounds each coordinate relative to that coordinate of the vertices
// (errors in the b's move p within the plane, not off it). So both thresholds are scaled by
// `magnitude`, the largest |coordinate| of the triangle's vertices on each axis; for magnitude 1
// this is the chapter's method exactly, and it keeps working from scene scales 1e-4 to 1e5.
// A later intersection test mixes the axes (it subtracts the new origin from far vertices), so
// no axis counts as smaller than 2^-8 of the largest one: a face lying in the plane z = 0 of a
// scene 1e5 wide still moves by 1e5 * 2^-24 = 0.006 instead of a denormal that the subtraction
// of a large coordinate would erase.
inline constexpr float kOffsetIntScale = 256.0f;
inline constexpr float kOffsetFloatScale = 1.0f / 65536.0f;
inline constexpr float kOffsetOrigin = 1.0f / 32.0f;
inline constexpr float kOffsetAxisFloor = 1.0f / 256.0f;

// p: a point on a triangle, computed from barycentrics (not o + t d, whose error grows with t).
// n: unit geometric normal pointing to the side the new ray leaves into.
inline glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& n, const glm::vec3& magnitude) {
  const float floor = kOffsetAxisFloor * std::max(std::max(magnitude.x, magnitude.y), magnitude.z);
  glm::vec3 out;
  for (int a = 0; a < 3; ++a) {
    const float pa = p[a];
    const float scale = std::max(magnitude[a], floor);
    if (std::fabs(pa) < kOffsetOrigin * scale) {
      out[a] = pa + kOffsetFloatScale * scale * n[a];
    } else {
      // Adding ulps moves away from zero for positive bits and towards it for negative ones,
      // so the step takes the sign of p; bits of a finite non-zero float never wrap here.
      const int32_t ulps = static_cast<int32_t>(kOffsetIntScale * n[a]);
      const int32_t bits = std::bit_cast<int32_t>(pa);
      out[a] = std::bit_cast<float>(bits + (pa < 0.0f ? -ulps : ulps));
    }
  }
  return out;
}

}  // namespace pr::rt
