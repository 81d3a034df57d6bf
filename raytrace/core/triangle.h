// Watertight ray-triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
// Intersection", JCGT 2013): the vertices are translated to the ray origin, sheared and scaled
// so the ray becomes the +z axis, and the 2D edge functions decide inside/outside. Called from
// the BVH leaves (bvh.cpp) for every tracer; a shared edge is computed from the same two
// transformed vertices in both triangles, so a ray through it hits at least one of them.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "raytrace/core/ray.h"

namespace pr::rt {

// Component K of a vector, resolved at compile time (glm's operator[] switches at run time).
template <int K>
inline float axis(const glm::vec3& v) {
  if constexpr (K == 0) return v.x;
  else if constexpr (K == 1) return v.y;
  else return v.z;
}

// Per-ray constants of the test (Woop et al. 2013, section 3). kz is the axis of the largest
// |direction| component, kx = (kz+1)%3, ky = (kx+1)%3. The paper swaps kx and ky when
// d[kz] < 0 to keep the winding for back-face culling; parrender never culls, and the swap
// only negates U, V, W and det together, so the barycentrics are bit-identical without it.
struct RayShear {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, 1.0f};
  int kz = 2;
  float sx = 0.0f, sy = 0.0f;
};

inline int dominantAxis(const glm::vec3& d) {
  const glm::vec3 a = glm::abs(d);
  return a.x >= a.y ? (a.x >= a.z ? 0 : 2) : (a.y >= a.z ? 1 : 2);
}

// The direction must be non-zero and finite (Bvh queries reject other rays before this).
inline RayShear makeRayShear(const Ray& ray) {
  RayShear s;
  s.origin = ray.origin;
  s.direction = ray.direction;
  s.kz = dominantAxis(ray.direction);
  const int kx = (s.kz + 1) % 3, ky = (kx + 1) % 3;
  const float dz = ray.direction[s.kz];
  s.sx = ray.direction[kx] / dz;
  s.sy = ray.direction[ky] / dz;
  return s;
}

struct TriangleHit {
  float t = 0.0f, u = 0.0f, v = 0.0f;
};

// Hit of the ray (as sheared for axis Kz) with triangle p0 p1 p2 for t in [tMin, tMax]; both
// faces count. Degenerate triangles (det = 0) and NaN inputs never hit: every comparison below
// is false for NaN and the final interval test rejects it.
template <int Kz>
inline bool intersectTriangle(const RayShear& s, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tMin, float tMax, TriangleHit& out) {
  constexpr int Kx = (Kz + 1) % 3, Ky = (Kx + 1) % 3;
  // Vertices relative to the ray origin, then sheared so the ray runs along +z (eq. 1-3).
  const glm::vec3 a = p0 - s.origin, b = p1 - s.origin, c = p2 - s.origin;
  const float az = axis<Kz>(a), bz = axis<Kz>(b), cz = axis<Kz>(c);  // eq. 2
  const float ax = axis<Kx>(a) - s.sx * az, ay = axis<Ky>(a) - s.sy * az;
  const float bx = axis<Kx>(b) - s.sx * bz, by = axis<Ky>(b) - s.sy * bz;
  const float cx = axis<Kx>(c) - s.sx * cz, cy = axis<Ky>(c) - s.sy * cz;

  // Scaled barycentric coordinates: edge functions of the edges opposite p0, p1, p2.
  float u = cx * by - cy * bx;
  float v = ax * cy - ay * cx;
  float w = bx * ay - by * ax;
  // An edge function of exactly 0 may be a rounding artefact (the ray through an edge or a
  // vertex): recompute in double, where the products of two floats are exact and the difference
  // rounds once, so its sign is exact (section 3.3).
  if (u == 0.0f || v == 0.0f || w == 0.0f) {
    u = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
    v = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
    w = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
  }
  // Inside when all three share a sign (either winding); a zero counts for both sides, so a
  // ray through a shared edge hits both neighbours and the tie-break picks one.
  if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
  const float det = u + v + w;
  if (det == 0.0f) return false;  // degenerate in ray space, or the ray lies in its plane

  // Hit distance from the plane equation, t = n.(p0 - o) / n.d with n = (p1-p0) x (p2-p0),
  // not from the paper's T / det (eq. 5): T interpolates the sheared z of the vertices, which
  // for a triangle much larger than its distance to the origin (a ground quad 1e4 long seen
  // from 1 above it) cancels catastrophically and misplaces the hit by whole units. The plane
  // form errs by a few ulps of |p0 - o|. It runs only for the few triangles that pass the
  // inside test, and uses no reciprocal approximation, so every PE computes the same t.
  const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
  const float denominator = glm::dot(n, s.direction);
  if (denominator == 0.0f) return false;
  const float t = glm::dot(n, a) / denominator;
  if (!(t >= tMin && t <= tMax)) return false;
  out.t = t;
  out.u = v / det;
  out.v = w / det;
  return true;
}

// Run-time dispatch on the shear axis, for callers outside the templated traversal (tests,
// single triangle checks). The BVH dispatches once per ray instead.
inline bool intersectTriangle(const RayShear& s, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tMin, float tMax, TriangleHit& out) {
  switch (s.kz) {
    case 0: return intersectTriangle<0>(s, p0, p1, p2, tMin, tMax, out);
    case 1: return intersectTriangle<1>(s, p0, p1, p2, tMin, tMax, out);
    default: return intersectTriangle<2>(s, p0, p1, p2, tMin, tMax, out);
  }
}

}  // namespace pr::rt
