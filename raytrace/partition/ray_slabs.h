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

// Four boxes for RaySlabs::overlapsAny, one lane each, coordinates by axis (lo[axis][lane]).
// A group of fewer boxes repeats one of them in the spare lanes.
struct SlabBoxes4 {
  alignas(16) float lo[3][4];
  alignas(16) float hi[3][4];

  // The first min(4, n) boxes of b, grown by `grow` on every side; n >= 1.
  static SlabBoxes4 of(const scene::Bounds* b, size_t n, float grow = 0.0f) {
    SlabBoxes4 g;
    for (size_t lane = 0; lane < 4; ++lane) {
      const scene::Bounds& box = b[std::min(lane, n - 1)];
      for (int a = 0; a < 3; ++a) {
        g.lo[a][lane] = box.min[a] - grow;
        g.hi[a][lane] = box.max[a] + grow;
      }
    }
    return g;
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
    const glm::vec3 inverse(reciprocal(d.x), reciprocal(d.y), reciprocal(d.z));
    origin_ = _mm_setr_ps(ray.origin.x, ray.origin.y, ray.origin.z, 0.0f);
    inverse_ = _mm_setr_ps(inverse.x, inverse.y, inverse.z, 1.0f);
    parallel_ = _mm_cmpeq_ps(_mm_setr_ps(d.x, d.y, d.z, 1.0f), _mm_setzero_ps());  // lanes with d == 0
    for (int a = 0; a < 3; ++a) {
      axis_[a] = d[a] == 0.0f ? Axis::Parallel : std::isinf(inverse[a]) ? Axis::Free : Axis::Slab;
      originAxis_[a] = _mm_set1_ps(ray.origin[a]);
      inverseAxis_[a] = _mm_set1_ps(axis_[a] == Axis::Slab ? inverse[a] : 0.0f);
    }
  }

  // t: the entry when reached.
  bool entry(const SlabBox& box, float& t) const {
    float near, far;
    interval(box, near, far);
    t = std::max(near, tMin_);
    return t <= std::min(far, tMax_);
  }
  // Whether the ray touches any of the four boxes for some t in [t0, t1]: entry()'s test of
  // the ray clipped to [t0, t1], with the boxes in the lanes, so a voxel's content costs one
  // pass per four boxes.
  // An axis whose reciprocal overflows (|d| below 2^-128) limits nothing here: conservative.
  bool overlapsAny(const SlabBoxes4& boxes, float t0, float t1) const {
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 near = _mm_sub_ps(_mm_setzero_ps(), inf), far = inf;
    __m128 inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int a = 0; a < 3; ++a) {
      const __m128 l = _mm_load_ps(boxes.lo[a]), h = _mm_load_ps(boxes.hi[a]);
      if (axis_[a] == Axis::Slab) {
        // Finite boxes and a finite reciprocal: no 0 * inf, so no NaN.
        const __m128 ta = _mm_mul_ps(_mm_sub_ps(l, originAxis_[a]), inverseAxis_[a]);
        const __m128 tb = _mm_mul_ps(_mm_sub_ps(h, originAxis_[a]), inverseAxis_[a]);
        near = _mm_max_ps(near, _mm_min_ps(ta, tb));
        far = _mm_min_ps(far, _mm_max_ps(ta, tb));
      } else if (axis_[a] == Axis::Parallel) {
        inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmple_ps(l, originAxis_[a]), _mm_cmple_ps(originAxis_[a], h)));
      }
    }
    // Widened as in interval(): after the max and min over the axes, since the widening is
    // monotonic. An infinite near distance becomes NaN, which fails the comparison: such a
    // box is not reached at any finite t.
    const __m128 absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 slack = _mm_set1_ps(kSlack);
    near = _mm_sub_ps(near, _mm_mul_ps(_mm_and_ps(near, absMask), slack));
    far = _mm_add_ps(far, _mm_mul_ps(_mm_and_ps(far, absMask), slack));
    near = _mm_max_ps(near, _mm_set1_ps(t0));
    far = _mm_min_ps(far, _mm_set1_ps(t1));
    return _mm_movemask_ps(_mm_and_ps(inside, _mm_cmple_ps(near, far))) != 0;
  }

 private:
  // The ray's parameters in the box (widened): near > far when it misses.
  static constexpr float kUlp = 0x1p-24f;
  static constexpr float kSlack = 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);

  void interval(const SlabBox& box, float& near, float& far) const {
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
  // Per axis for overlapsAny: Slab, the usual test; Parallel (d = 0), the origin inside the
  // slab or the box is missed; Free (|d| so small that 1 / d overflows), no limit.
  enum class Axis : uint8_t { Slab, Parallel, Free };
  Axis axis_[3];
  __m128 originAxis_[3], inverseAxis_[3];  // splatted; the reciprocal 0 on an axis that is not Slab
  float tMin_, tMax_;
};

}  // namespace pr::rt
