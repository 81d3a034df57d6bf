// RaySlabs: the slab test of one ray against many axis-aligned boxes, three axes in one SSE
// register, conservative (never misses a box the ray touches, never reports an entry later
// than the box's first point on the ray). Used by the owner directory (owner_directory.h) and
// the voxels' content boxes (voxel_split.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <emmintrin.h>  // SSE2: part of every x86-64 target

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"

namespace pr::rt {

// A box as 4 lanes for RaySlabs' SSE test; lane 3 is (-inf, +inf), which never limits.
struct SlabBox {
  alignas(16) float lo[4];
  alignas(16) float hi[4];

  // b grown by `grow` on every side.
  static SlabBox of(const scene::Bounds& b, float grow = 0.0f) {
    SlabBox box;
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = b.min[a] - grow;
      box.hi[a] = b.max[a] + grow;
    }
    box.lo[3] = -std::numeric_limits<float>::infinity();
    box.hi[3] = std::numeric_limits<float>::infinity();
    return box;
  }
};

// The slab test of one ray against many boxes, three axes in one SSE register. Rounding of
// (b - o) * (1 / d) is below gamma(3) relative (Ize 2013): the near distance is moved towards
// the origin and the far one away by 2 gamma(3) of their size, so the entry is never later
// than the box's first point on the ray and no box the ray touches is missed. An axis the ray
// is parallel to limits nothing when the origin lies in the slab and excludes the box when
// not (its reciprocal is never used there, so no lane computes 0 * inf).
class RaySlabs {
 public:
  // Built in registers: eight scalar stores read back as two vectors cannot be forwarded from
  // the store buffer, and that stall stood out in every object-space walk's profile.
  explicit RaySlabs(const Ray& ray) : tMin_(ray.tMin), tMax_(ray.tMax) {
    const glm::vec3 d = ray.direction;
    auto reciprocal = [](float x) { return x == 0.0f ? 0.0f : 1.0f / x; };
    origin_ = _mm_setr_ps(ray.origin.x, ray.origin.y, ray.origin.z, 0.0f);
    inverse_ = _mm_setr_ps(reciprocal(d.x), reciprocal(d.y), reciprocal(d.z), 1.0f);
    parallel_ = _mm_cmpeq_ps(_mm_setr_ps(d.x, d.y, d.z, 1.0f), _mm_setzero_ps());  // lanes with d == 0
  }

  // t: the entry when reached.
  bool entry(const SlabBox& box, float& t) const {
    float near, far;
    interval(box, near, far);
    t = std::max(near, tMin_);
    return t <= std::min(far, tMax_);
  }
  // Whether the ray touches the box for some t in [t0, t1].
  bool overlaps(const SlabBox& box, float t0, float t1) const {
    float near, far;
    interval(box, near, far);
    return std::max(near, t0) <= std::min(far, t1);
  }

 private:
  // The ray's parameters in the box (widened): near > far when it misses.
  void interval(const SlabBox& box, float& near, float& far) const {
    constexpr float kUlp = 0x1p-24f;
    constexpr float kSlack = 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);
    const __m128 l = _mm_load_ps(box.lo), h = _mm_load_ps(box.hi);
    const __m128 a = _mm_mul_ps(_mm_sub_ps(l, origin_), inverse_);
    const __m128 b = _mm_mul_ps(_mm_sub_ps(h, origin_), inverse_);
    const __m128 absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 slack = _mm_set1_ps(kSlack);
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 minusInf = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    // A direction component so small that its reciprocal is infinite, with the origin on the
    // face: 0 * inf is NaN, which limits nothing (-inf as a near, +inf as a far distance).
    const __m128 nanA = _mm_cmpunord_ps(a, a), nanB = _mm_cmpunord_ps(b, b);
    const __m128 aNear = _mm_or_ps(_mm_and_ps(nanA, minusInf), _mm_andnot_ps(nanA, a));
    const __m128 bNear = _mm_or_ps(_mm_and_ps(nanB, minusInf), _mm_andnot_ps(nanB, b));
    const __m128 aFar = _mm_or_ps(_mm_and_ps(nanA, inf), _mm_andnot_ps(nanA, a));
    const __m128 bFar = _mm_or_ps(_mm_and_ps(nanB, inf), _mm_andnot_ps(nanB, b));
    __m128 tNear = _mm_min_ps(aNear, bNear), tFar = _mm_max_ps(aFar, bFar);
    tNear = _mm_sub_ps(tNear, _mm_mul_ps(_mm_and_ps(tNear, absMask), slack));
    tFar = _mm_add_ps(tFar, _mm_mul_ps(_mm_and_ps(tFar, absMask), slack));
    // Parallel axes: (-inf, +inf) inside the slab, (+inf, -inf) outside.
    const __m128 inside = _mm_and_ps(_mm_cmple_ps(l, origin_), _mm_cmple_ps(origin_, h));
    const __m128 parallelNear = _mm_or_ps(_mm_and_ps(inside, minusInf), _mm_andnot_ps(inside, inf));
    const __m128 parallelFar = _mm_or_ps(_mm_and_ps(inside, inf), _mm_andnot_ps(inside, minusInf));
    tNear = _mm_or_ps(_mm_and_ps(parallel_, parallelNear), _mm_andnot_ps(parallel_, tNear));
    tFar = _mm_or_ps(_mm_and_ps(parallel_, parallelFar), _mm_andnot_ps(parallel_, tFar));
    alignas(16) float n[4], f[4];
    _mm_store_ps(n, tNear);
    _mm_store_ps(f, tFar);
    near = std::max(std::max(n[0], n[1]), n[2]);
    far = std::min(std::min(f[0], f[1]), f[2]);
  }

  __m128 origin_, inverse_, parallel_;  // parallel_: all bits set in the lanes where d = 0
  float tMin_, tMax_;
};

}  // namespace pr::rt
