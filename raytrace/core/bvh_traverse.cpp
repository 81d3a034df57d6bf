// BVH queries: closest hit and any hit (shadow). Called by every tracer for every ray, on the
// PE that holds the BVH (the world-model BVH in image-space, a PE's own BVH in the partitioned
// tracers); read-only, so any number of PEs may query one Bvh at once.
// Each 8-wide node is one slab test of all its children (AVX2 where the processor has it, two
// 4-lane SSE tests elsewhere; bvh_traverse_lanes.inc), whose near and far planes are picked
// once per ray by the sign of the direction; leaves test four triangles at once
// (triangle4.h); a closest-hit query visits hit children nearest first and prunes subtrees that
// start beyond the best hit so far, an any-hit query visits them farthest first; a child left
// on the stack is prefetched as it is pushed.
#include <algorithm>
#include <cmath>
#include <string>

#include <immintrin.h>

#include "common/util/cpu_features.h"
#include "common/util/error.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/triangle4.h"

namespace pr::rt {
namespace {

// The build's binary depth is at most 60 (bvh_build.cpp); a wide node covers at least one
// binary level and leaves at most kBvhWidth - 1 siblings pending.
constexpr int kStackSize = (kBvhWidth - 1) * 60 + kBvhWidth;

// Robust slab test (Ize 2013, "Robust BVH ray traversal"; pbrt-v4): the far distances are
// scaled by 1 + 2 gamma(3), gamma(n) = n u / (1 - n u) with u = 2^-24, which bounds the
// rounding of (b - o) * (1/d), so a box the ray touches is never missed. The scale is folded
// into a far reciprocal, (1/d) * scale, computed once per ray: four roundings, as with the
// scale applied last, which 1 + 6u still covers ((1 - u)^-4 < 1 + 4.1u), and one multiply less
// per node.
constexpr float kUlp = 0x1p-24f;
constexpr float kSlabScale = 1.0f + 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);

// A direction component of 0 gives an infinite reciprocal, and a box face through the origin
// along that axis then gives 0 * inf = NaN: the ray lies in the face's plane. Closed boxes
// count such a ray as inside the slab, so a NaN distance must constrain nothing. SSE's (and
// AVX's) max and min return their second operand when either is NaN, so every distance is
// combined as the first operand with a non-NaN running bound as the second (tMin - slack for
// the entry, the best hit so far or tMax for the exit; see slab()). Clamping the component
// to a tiny value instead gave a distance of exactly 0 and lost boxes whose far face held the
// ray, and with them ties between triangles that meet in that plane.

// The triangle test and the slab test round differently: a hit's t can come out a little
// smaller than the computed entry distance of its own box. The error of both is a few ulps of
// the coordinates' magnitude divided by |d|, so boxes are compared with a slack of 2^-18 of
// that (32 ulps). The slack only makes pruning more conservative: results never change, and
// with it they do not depend on which BVH (which partitioning) holds the triangle.
constexpr float kSlackFraction = 0x1p-18f;

// The ray's constants of the slab test, scalar; each width splats them into its lanes.
struct RaySetup {
  float origin[3];
  float invDir[3];
  float farInvDir[3];  // invDir * kSlabScale
  float lo;     // tMin - slack
  float slack;
  int nearRow[3];  // BvhNode::bounds row of the entry plane per axis: min for d >= 0, else max
  int farRow[3];
};

inline RaySetup makeRaySetup(const Ray& ray, float magnitude) {
  RaySetup r;
  for (int a = 0; a < 3; ++a) {
    const float d = ray.direction[a];
    r.origin[a] = ray.origin[a];
    r.invDir[a] = 1.0f / d;
    r.farInvDir[a] = r.invDir[a] * kSlabScale;
    const bool negative = std::signbit(d);
    r.nearRow[a] = negative ? 3 + a : a;
    r.farRow[a] = negative ? a : 3 + a;
  }
  const glm::vec3 ad = glm::abs(ray.direction), ao = glm::abs(ray.origin);
  const float scale = std::max({magnitude, ao.x, ao.y, ao.z});
  r.slack = kSlackFraction * scale / std::max({ad.x, ad.y, ad.z});
  r.lo = ray.tMin - r.slack;
  return r;
}

bool usable(const Ray& ray) {
  const glm::vec3 d = ray.direction, o = ray.origin;
  const bool finiteRay = std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) &&
                         std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.z);
  return finiteRay && (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f) && ray.tMin <= ray.tMax;
}

struct StackEntry {
  uint32_t ref;
  // The child's entry distance, which closestHit's pruning reads; anyHit, which orders farthest
  // first, keeps it negated and never reads it.
  float tEntry;
};

// What a query reads of a Bvh.
struct BvhQuery {
  const BvhNode* nodes;
  const BvhLeafBlock* blocks;
  uint32_t root;
  float magnitude;
  const AlphaTest* alpha;
};

namespace sse {
#define PR_BVH_LANES 4
#include "raytrace/core/bvh_traverse_lanes.inc"
#undef PR_BVH_LANES
}  // namespace sse

// The same queries with one AVX2 slab test per node (run only where the processor has it).
// Everything defined here has internal linkage, so no AVX code reaches other callers.
PR_BEGIN_AVX2
namespace avx2 {
#define PR_BVH_LANES 8
#include "raytrace/core/bvh_traverse_lanes.inc"
#undef PR_BVH_LANES
}  // namespace avx2
PR_END_AVX2

}  // namespace

namespace {
int g_slabLanes = hasAvx2() ? avx2::kLanes : sse::kLanes;
}  // namespace

int bvhSlabLanes() { return g_slabLanes; }

void setBvhSlabLanes(int lanes) {
  if (lanes != sse::kLanes && lanes != avx2::kLanes)
    throw InputError("BVH slab test: " + std::to_string(lanes) + " lanes (4 or 8)");
  if (lanes == avx2::kLanes && !hasAvx2()) throw InputError("BVH slab test: 8 lanes need AVX2, which this processor lacks");
  g_slabLanes = lanes;
}

bool Bvh::intersect(const Ray& ray, Hit& hit) const {
  if (empty() || !usable(ray)) return false;
  const BvhQuery q{nodes_.data(), leafBlocks_.data(), root_, magnitude_, alpha_.get()};
  return g_slabLanes == avx2::kLanes ? avx2::intersect(q, ray, hit) : sse::intersect(q, ray, hit);
}

bool Bvh::occluded(const Ray& ray) const {
  if (empty() || !usable(ray)) return false;
  const BvhQuery q{nodes_.data(), leafBlocks_.data(), root_, magnitude_, alpha_.get()};
  return g_slabLanes == avx2::kLanes ? avx2::occluded(q, ray) : sse::occluded(q, ray);
}

}  // namespace pr::rt
