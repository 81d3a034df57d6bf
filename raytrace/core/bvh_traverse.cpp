// BVH queries: closest hit and any hit (shadow). Called by every tracer for every ray, on the
// PE that holds the BVH (the world-model BVH in image-space, a PE's own BVH in the partitioned
// tracers); read-only, so any number of PEs may query one Bvh at once.
// Traversal visits the nearer child first (by the children's entry distances, which follow the
// sign of the direction on the split axis) and prunes subtrees that start beyond the best hit.
#include <algorithm>
#include <cmath>

#include "raytrace/core/bvh.h"
#include "raytrace/core/triangle.h"

namespace pr::rt {
namespace {

// Depth bound of the build (bvh_build.cpp: 32 SAH levels, then median splits of at most 2^32
// triangles) plus margin; one entry per level can be pending.
constexpr int kStackSize = 96;

// Robust slab test (Ize 2013, "Robust BVH ray traversal"; pbrt-v4): the far distances are
// scaled by 1 + 2 gamma(3), gamma(n) = n u / (1 - n u) with u = 2^-24, which bounds the
// rounding of (b - o) * (1/d), so a box the ray touches is never missed.
constexpr float kUlp = 0x1p-24f;
constexpr float kSlabScale = 1.0f + 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);

// Smallest |direction| component used for the reciprocal: a zero component would give
// 0 * inf = NaN for a box face through the origin; 1e-30 keeps every product finite for
// scenes up to 1e8 in size and is far below any direction a renderer produces.
constexpr float kMinDirection = 1e-30f;

// The triangle test and the slab test round differently: a hit's t can come out a little
// smaller than the computed entry distance of its own box. The error of both is a few ulps of
// the coordinates' magnitude divided by |d|, so boxes are compared with a slack of 2^-18 of
// that (32 ulps). The slack only makes pruning more conservative: results never change, and
// with it they do not depend on which BVH (which partitioning) holds the triangle.
constexpr float kSlackFraction = 0x1p-18f;

struct BoxRay {
  glm::vec3 origin;
  glm::vec3 invDir;
  float lo;     // tMin - slack
  float slack;
};

BoxRay makeBoxRay(const Ray& ray, float magnitude) {
  BoxRay r;
  r.origin = ray.origin;
  for (int a = 0; a < 3; ++a) {
    const float d = ray.direction[a];
    r.invDir[a] = 1.0f / (std::fabs(d) < kMinDirection ? std::copysign(kMinDirection, d) : d);
  }
  const glm::vec3 ad = glm::abs(ray.direction), ao = glm::abs(ray.origin);
  const float scale = std::max({magnitude, ao.x, ao.y, ao.z});
  r.slack = kSlackFraction * scale / std::max({ad.x, ad.y, ad.z});
  r.lo = ray.tMin - r.slack;
  return r;
}

// Entry distance of the ray into the node's box if the box overlaps [lo, hi + slack], where hi
// is the best hit so far (or tMax).
inline bool slab(const BvhNode& node, const BoxRay& r, float hi, float& tEntry) {
  const glm::vec3 t0 = (node.boundsMin - r.origin) * r.invDir;
  const glm::vec3 t1 = (node.boundsMax - r.origin) * r.invDir;
  const glm::vec3 tNear = glm::min(t0, t1), tFar = glm::max(t0, t1);
  const float enter = std::max(std::max(tNear.x, tNear.y), std::max(tNear.z, r.lo));
  const float leave = std::min(std::min(tFar.x, tFar.y), tFar.z) * kSlabScale;
  tEntry = enter;
  return enter <= std::min(leave, hi) + r.slack;
}

bool usable(const Ray& ray) {
  const glm::vec3 d = ray.direction, o = ray.origin;
  const bool finiteRay = std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) &&
                         std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.z);
  return finiteRay && (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f) && ray.tMin <= ray.tMax;
}

struct StackEntry {
  uint32_t node;
  float tEntry;
};

}  // namespace

template <int Kz>
bool Bvh::intersectK(const Ray& ray, Hit& hit) const {
  const RayShear shear = makeRayShear(ray);
  const BoxRay boxRay = makeBoxRay(ray, magnitude_);
  float bestT = ray.tMax;
  uint32_t bestTriangle = kNoTriangle;
  float bestU = 0.0f, bestV = 0.0f;

  StackEntry stack[kStackSize];
  int sp = 0;
  uint32_t current = 0;
  float tEntry;
  if (!slab(nodes_[0], boxRay, bestT, tEntry)) return false;
  for (;;) {
    const BvhNode& node = nodes_[current];
    if (node.isLeaf()) {
      const BvhTriangle* tri = triangles_.data() + node.offset;
      for (uint32_t i = 0; i < node.count; ++i, ++tri) {
        TriangleHit th;
        if (!intersectTriangle<Kz>(shear, tri->p0, tri->p1, tri->p2, ray.tMin, bestT, th)) continue;
        // th.t <= bestT here; equal t keeps the lower triangle index (Hit::closerThan).
        if (th.t < bestT || tri->triangle < bestTriangle) {
          bestT = th.t;
          bestTriangle = tri->triangle;
          bestU = th.u;
          bestV = th.v;
        }
      }
    } else {
      const uint32_t first = current + 1, second = node.offset;
      float t0, t1;
      const bool hit0 = slab(nodes_[first], boxRay, bestT, t0);
      const bool hit1 = slab(nodes_[second], boxRay, bestT, t1);
      if (hit0 && hit1) {
        if (t0 <= t1) {
          stack[sp++] = {second, t1};
          current = first;
        } else {
          stack[sp++] = {first, t0};
          current = second;
        }
        continue;
      }
      if (hit0 || hit1) {
        current = hit0 ? first : second;
        continue;
      }
    }
    // Next pending subtree that may still hold a hit no farther than the best one.
    for (;;) {
      if (sp == 0) {
        if (bestTriangle == kNoTriangle) return false;
        hit = Hit{bestT, bestTriangle, bestU, bestV};
        return true;
      }
      const StackEntry e = stack[--sp];
      if (e.tEntry <= bestT + boxRay.slack) {
        current = e.node;
        break;
      }
    }
  }
}

template <int Kz>
bool Bvh::occludedK(const Ray& ray) const {
  const RayShear shear = makeRayShear(ray);
  const BoxRay boxRay = makeBoxRay(ray, magnitude_);
  const float tMax = ray.tMax;
  uint32_t stack[kStackSize];
  int sp = 0;
  uint32_t current = 0;
  float tEntry;
  if (!slab(nodes_[0], boxRay, tMax, tEntry)) return false;
  for (;;) {
    const BvhNode& node = nodes_[current];
    if (node.isLeaf()) {
      const BvhTriangle* tri = triangles_.data() + node.offset;
      for (uint32_t i = 0; i < node.count; ++i, ++tri) {
        TriangleHit th;
        if (intersectTriangle<Kz>(shear, tri->p0, tri->p1, tri->p2, ray.tMin, tMax, th)) return true;
      }
    } else {
      const uint32_t first = current + 1, second = node.offset;
      float t0, t1;
      const bool hit0 = slab(nodes_[first], boxRay, tMax, t0);
      const bool hit1 = slab(nodes_[second], boxRay, tMax, t1);
      if (hit0 && hit1) {
        stack[sp++] = t0 <= t1 ? second : first;
        current = t0 <= t1 ? first : second;
        continue;
      }
      if (hit0 || hit1) {
        current = hit0 ? first : second;
        continue;
      }
    }
    if (sp == 0) return false;
    current = stack[--sp];
  }
}

bool Bvh::intersect(const Ray& ray, Hit& hit) const {
  if (nodes_.empty() || !usable(ray)) return false;
  switch (dominantAxis(ray.direction)) {
    case 0: return intersectK<0>(ray, hit);
    case 1: return intersectK<1>(ray, hit);
    default: return intersectK<2>(ray, hit);
  }
}

bool Bvh::occluded(const Ray& ray) const {
  if (nodes_.empty() || !usable(ray)) return false;
  switch (dominantAxis(ray.direction)) {
    case 0: return occludedK<0>(ray);
    case 1: return occludedK<1>(ray);
    default: return occludedK<2>(ray);
  }
}

}  // namespace pr::rt
