// BVH queries: closest hit and any hit (shadow). Called by every tracer for every ray, on the
// PE that holds the BVH (the world-model BVH in image-space, a PE's own BVH in the partitioned
// tracers); read-only, so any number of PEs may query one Bvh at once.
// Each wide node is one 4-lane SSE slab test per four children, whose near and far planes are
// picked once per ray by the sign of the direction; leaves test four triangles at once
// (triangle4.h); hit children are visited nearest first, and subtrees that start
// beyond the best hit so far are pruned.
#include <algorithm>
#include <cmath>
#include <limits>

#include <emmintrin.h>  // SSE2: part of every x86-64 target

#include "raytrace/core/bvh.h"
#include "raytrace/core/triangle4.h"

namespace pr::rt {
namespace {

// The build's binary depth is at most 60 (bvh_build.cpp); a wide node covers at least one
// binary level and leaves at most kBvhWidth - 1 siblings pending.
constexpr int kStackSize = (kBvhWidth - 1) * 60 + kBvhWidth;
constexpr int kGroups = kBvhWidth / 4;

// Robust slab test (Ize 2013, "Robust BVH ray traversal"; pbrt-v4): the far distances are
// scaled by 1 + 2 gamma(3), gamma(n) = n u / (1 - n u) with u = 2^-24, which bounds the
// rounding of (b - o) * (1/d), so a box the ray touches is never missed.
constexpr float kUlp = 0x1p-24f;
constexpr float kSlabScale = 1.0f + 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);

// A direction component of 0 gives an infinite reciprocal, and a box face through the origin
// along that axis then gives 0 * inf = NaN: the ray lies in the face's plane. Closed boxes
// count such a ray as inside the slab, so a NaN distance must constrain nothing. SSE's max and
// min return their second operand when either is NaN, so every distance is combined as the
// first operand with a finite running bound as the second (see slab()). Clamping the component
// to a tiny value instead gave a distance of exactly 0 and lost boxes whose far face held the
// ray, and with them ties between triangles that meet in that plane.
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// The triangle test and the slab test round differently: a hit's t can come out a little
// smaller than the computed entry distance of its own box. The error of both is a few ulps of
// the coordinates' magnitude divided by |d|, so boxes are compared with a slack of 2^-18 of
// that (32 ulps). The slack only makes pruning more conservative: results never change, and
// with it they do not depend on which BVH (which partitioning) holds the triangle.
constexpr float kSlackFraction = 0x1p-18f;

struct BoxRay {
  __m128 origin[3];
  __m128 invDir[3];
  __m128 lo;     // tMin - slack
  __m128 slack;
  int nearRow[3];  // BvhNode::bounds row of the entry plane per axis: min for d >= 0, else max
  int farRow[3];
};

BoxRay makeBoxRay(const Ray& ray, float magnitude) {
  BoxRay r;
  for (int a = 0; a < 3; ++a) {
    const float d = ray.direction[a];
    r.origin[a] = _mm_set1_ps(ray.origin[a]);
    r.invDir[a] = _mm_set1_ps(1.0f / d);
    const bool negative = std::signbit(d);
    r.nearRow[a] = negative ? 3 + a : a;
    r.farRow[a] = negative ? a : 3 + a;
  }
  const glm::vec3 ad = glm::abs(ray.direction), ao = glm::abs(ray.origin);
  const float scale = std::max({magnitude, ao.x, ao.y, ao.z});
  const float slack = kSlackFraction * scale / std::max({ad.x, ad.y, ad.z});
  r.slack = _mm_set1_ps(slack);
  r.lo = _mm_set1_ps(ray.tMin - slack);
  return r;
}

// Slab test of the children against [tMin, hi] (hi: the best hit so far, or tMax), widened
// as described above, four lanes at a time. Returns the lane mask of hit children and their
// entry distances.
inline int slab(const BvhNode& node, const BoxRay& r, float hi, __m128 (&tEntry)[kGroups]) {
  const __m128 hiVec = _mm_set1_ps(hi);
  const __m128 scale = _mm_set1_ps(kSlabScale);
  const __m128 infinity = _mm_set1_ps(kInfinity);
  int mask = 0;
  for (int g = 0; g < kGroups; ++g) {
    const int o = 4 * g;
    const __m128 nx = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.nearRow[0]] + o), r.origin[0]), r.invDir[0]);
    const __m128 ny = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.nearRow[1]] + o), r.origin[1]), r.invDir[1]);
    const __m128 nz = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.nearRow[2]] + o), r.origin[2]), r.invDir[2]);
    const __m128 fx = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.farRow[0]] + o), r.origin[0]), r.invDir[0]);
    const __m128 fy = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.farRow[1]] + o), r.origin[1]), r.invDir[1]);
    const __m128 fz = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.farRow[2]] + o), r.origin[2]), r.invDir[2]);
    // Each distance first, the running bound second: a NaN distance (see kInfinity) drops out.
    const __m128 enter = _mm_max_ps(nz, _mm_max_ps(ny, _mm_max_ps(nx, r.lo)));
    const __m128 leave = _mm_mul_ps(_mm_min_ps(fz, _mm_min_ps(fy, _mm_min_ps(fx, infinity))), scale);
    const __m128 limit = _mm_add_ps(_mm_min_ps(leave, hiVec), r.slack);
    tEntry[g] = enter;
    mask |= _mm_movemask_ps(_mm_cmple_ps(enter, limit)) << o;
  }
  return mask;
}

bool usable(const Ray& ray) {
  const glm::vec3 d = ray.direction, o = ray.origin;
  const bool finiteRay = std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) &&
                         std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.z);
  return finiteRay && (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f) && ray.tMin <= ray.tMax;
}

struct StackEntry {
  uint32_t ref;
  float tEntry;
};

// Continues with the nearest hit child and pushes the others farthest first, so they pop in
// order of entry distance. mask has at least one bit set.
inline uint32_t orderChildren(const BvhNode& node, int mask, const __m128 (&tEntry)[kGroups], StackEntry* stack,
                              int& sp) {
  const int first = __builtin_ctz(unsigned(mask));
  mask &= mask - 1;
  if (mask == 0) return node.child[first];  // one child hit: the common case deep in the tree
  alignas(16) float t[kBvhWidth];
  for (int g = 0; g < kGroups; ++g) _mm_store_ps(t + 4 * g, tEntry[g]);
  const int second = __builtin_ctz(unsigned(mask));
  mask &= mask - 1;
  if (mask == 0) {
    const bool firstNearer = t[first] <= t[second];
    const int nearLane = firstNearer ? first : second, farLane = firstNearer ? second : first;
    stack[sp++] = {node.child[farLane], t[farLane]};
    return node.child[nearLane];
  }
  // More: insertion by descending entry distance, then push all but the nearest.
  StackEntry hits[kBvhWidth];
  int n = 0;
  hits[n++] = {node.child[first], t[first]};
  mask |= 1 << second;
  while (mask != 0) {
    const int lane = __builtin_ctz(unsigned(mask));
    mask &= mask - 1;
    StackEntry e{node.child[lane], t[lane]};
    int i = n++;
    while (i > 0 && hits[i - 1].tEntry < e.tEntry) {
      hits[i] = hits[i - 1];
      --i;
    }
    hits[i] = e;
  }
  for (int i = 0; i < n - 1; ++i) stack[sp++] = hits[i];
  return hits[n - 1].ref;
}

}  // namespace

template <int Kz>
bool Bvh::intersectK(const Ray& ray, Hit& hit) const {
  const RayShear shear = makeRayShear(ray);
  const BoxRay boxRay = makeBoxRay(ray, magnitude_);
  const float slack = _mm_cvtss_f32(boxRay.slack);
  float bestT = ray.tMax;
  uint32_t bestTriangle = kNoTriangle;
  float bestU = 0.0f, bestV = 0.0f;
  const AlphaTest* alpha = alpha_.get();
  // Locals, so the compiler need not reload the vectors' data pointers after every store.
  const BvhNode* nodes = nodes_.data();
  const BvhTriangle* triangles = triangles_.data();

  StackEntry stack[kStackSize];
  int sp = 0;
  uint32_t ref = root_;
  for (;;) {
    if (!BvhRef::isLeaf(ref)) {
      __m128 tEntry[kGroups];
      const int mask = slab(nodes[ref], boxRay, bestT, tEntry);
      if (mask != 0) {
        ref = orderChildren(nodes[ref], mask, tEntry, stack, sp);
        continue;
      }
    } else {
      const BvhTriangle* tri = triangles + BvhRef::leafFirst(ref);
      const uint32_t count = BvhRef::leafCount(ref);
      for (uint32_t first = 0; first < count; first += kLeafLanes, tri += kLeafLanes) {
        alignas(16) float t[kLeafLanes], u[kLeafLanes], v[kLeafLanes];
        // In lane order, as one triangle after another: a lane counts only if it is no farther
        // than the best hit so far; equal t keeps the lower triangle index (Hit::closerThan).
        for (int mask = intersectLeaf<Kz>(shear, tri, std::min<uint32_t>(count - first, kLeafLanes), ray.tMin, bestT, t, u, v);
             mask != 0; mask &= mask - 1) {
          const int lane = __builtin_ctz(unsigned(mask));
          const uint32_t id = tri[lane].triangle;
          if (t[lane] <= bestT && (t[lane] < bestT || id < bestTriangle) && (!alpha || alpha->passes(id, u[lane], v[lane], ray))) {
            bestT = t[lane];
            bestTriangle = id;
            bestU = u[lane];
            bestV = v[lane];
          }
        }
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
      if (e.tEntry <= bestT + slack) {
        ref = e.ref;
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
  const AlphaTest* alpha = alpha_.get();
  const BvhNode* nodes = nodes_.data();
  const BvhTriangle* triangles = triangles_.data();
  StackEntry stack[kStackSize];
  int sp = 0;
  uint32_t ref = root_;
  for (;;) {
    if (!BvhRef::isLeaf(ref)) {
      __m128 tEntry[kGroups];
      int mask = slab(nodes[ref], boxRay, tMax, tEntry);
      if (mask != 0) {
        // Any hit ends the query, so the order of the children only matters for how soon one
        // is found: no sort, the first hit lane goes on, the others wait on the stack.
        const BvhNode& node = nodes[ref];
        ref = node.child[__builtin_ctz(unsigned(mask))];
        for (mask &= mask - 1; mask != 0; mask &= mask - 1) stack[sp++] = {node.child[__builtin_ctz(unsigned(mask))], 0.0f};
        continue;
      }
    } else {
      const BvhTriangle* tri = triangles + BvhRef::leafFirst(ref);
      const uint32_t count = BvhRef::leafCount(ref);
      for (uint32_t first = 0; first < count; first += kLeafLanes, tri += kLeafLanes) {
        alignas(16) float t[kLeafLanes], u[kLeafLanes], v[kLeafLanes];
        const int mask = intersectLeaf<Kz>(shear, tri, std::min<uint32_t>(count - first, kLeafLanes), ray.tMin, tMax, t, u, v);
        if (mask != 0 && !alpha) return true;
        for (int rest = mask; rest != 0; rest &= rest - 1) {
          const int lane = __builtin_ctz(unsigned(rest));
          if (alpha->passes(tri[lane].triangle, u[lane], v[lane], ray)) return true;
        }
      }
    }
    if (sp == 0) return false;
    ref = stack[--sp].ref;
  }
}

bool Bvh::intersect(const Ray& ray, Hit& hit) const {
  if (empty() || !usable(ray)) return false;
  switch (dominantAxis(ray.direction)) {
    case 0: return intersectK<0>(ray, hit);
    case 1: return intersectK<1>(ray, hit);
    default: return intersectK<2>(ray, hit);
  }
}

bool Bvh::occluded(const Ray& ray) const {
  if (empty() || !usable(ray)) return false;
  switch (dominantAxis(ray.direction)) {
    case 0: return occludedK<0>(ray);
    case 1: return occludedK<1>(ray);
    default: return occludedK<2>(ray);
  }
}

}  // namespace pr::rt
