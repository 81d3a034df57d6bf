// The owner directory's build (median split of the owners' box centres, one owner per leaf)
// and query (the owners a ray reaches, nearest first).
#include "raytrace/partition/owner_directory.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <emmintrin.h>  // SSE2: part of every x86-64 target

namespace pr::rt {
namespace {

// The slab test of one ray against many boxes, three axes in one SSE register. Rounding of
// (b - o) * (1 / d) is below gamma(3) relative (Ize 2013): the near distance is moved towards
// the origin and the far one away by 2 gamma(3) of their size, so the entry is never later
// than the box's first point on the ray and no box the ray touches is missed. An axis the ray
// is parallel to limits nothing when the origin lies in the slab and excludes the box when
// not (its reciprocal is never used there, so no lane computes 0 * inf).
class BoxSlabs {
 public:
  explicit BoxSlabs(const Ray& ray) : tMin_(ray.tMin), tMax_(ray.tMax) {
    alignas(16) float o[4], inv[4];
    alignas(16) uint32_t parallel[4] = {0, 0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      const float d = ray.direction[a];
      o[a] = ray.origin[a];
      inv[a] = d == 0.0f ? 0.0f : 1.0f / d;
      parallel[a] = d == 0.0f ? ~0u : 0u;
    }
    o[3] = 0.0f;
    inv[3] = 1.0f;
    origin_ = _mm_load_ps(o);
    inverse_ = _mm_load_ps(inv);
    parallel_ = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(parallel)));
  }

  bool entry(const float* lo, const float* hi, float& t) const {
    constexpr float kUlp = 0x1p-24f;
    constexpr float kSlack = 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);
    const __m128 l = _mm_load_ps(lo), h = _mm_load_ps(hi);
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
    const float t0 = std::max(std::max(n[0], n[1]), std::max(n[2], tMin_));
    const float t1 = std::min(std::min(f[0], f[1]), std::min(f[2], tMax_));
    t = t0;
    return t0 <= t1;
  }

 private:
  __m128 origin_, inverse_, parallel_;  // parallel_: all bits set in the lanes where d = 0
  float tMin_, tMax_;
};

}  // namespace

OwnerDirectory::OwnerDirectory(const ObjectAssignment& assignment) : ownsPieces_(size_t(assignment.pes()), false) {
  std::vector<scene::Bounds> ownerBounds(size_t(assignment.pes()));
  for (const ObjectPiece& p : assignment.pieces())
    if (!p.bounds.empty()) ownerBounds[size_t(p.owner)].extend(p.bounds);
  for (int o = 0; o < assignment.pes(); ++o) {
    scene::Bounds grown = ownerBounds[size_t(o)];
    if (grown.empty()) continue;
    grown.min -= glm::vec3(assignment.margin());
    grown.max += glm::vec3(assignment.margin());
    leaves_.push_back({grown, o});
    ownsPieces_[size_t(o)] = true;
  }
  if (leaves_.empty()) return;
  nodes_.reserve(2 * leaves_.size());
  nodes_.emplace_back();
  build(0, 0, uint32_t(leaves_.size()));
}

// Median split of the owners' box centres on their longest axis, one owner per leaf.
void OwnerDirectory::build(uint32_t node, uint32_t begin, uint32_t end) {
  scene::Bounds box, centres;
  for (uint32_t i = begin; i < end; ++i) {
    box.extend(leaves_[i].box);
    centres.extend(leaves_[i].box.center());
  }
  Node& n = nodes_[node];
  for (int a = 0; a < 3; ++a) {
    n.lo[a] = box.min[a];
    n.hi[a] = box.max[a];
  }
  n.lo[3] = -std::numeric_limits<float>::infinity();
  n.hi[3] = std::numeric_limits<float>::infinity();
  if (end - begin == 1) {
    n.leaf = true;
    n.first = begin;
    return;
  }
  const glm::vec3 extent = centres.max - centres.min;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(leaves_.begin() + begin, leaves_.begin() + mid, leaves_.begin() + end, [&](const Leaf& x, const Leaf& y) {
    const float cx = x.box.center()[axis], cy = y.box.center()[axis];
    return cx < cy || (cx == cy && x.owner < y.owner);
  });
  const auto left = uint32_t(nodes_.size());
  n.first = left;
  nodes_.emplace_back();  // invalidates n
  nodes_.emplace_back();
  build(left, begin, mid);
  build(left + 1, mid, end);
}

// Nodes in order of their entry (a heap): a node's entry is no farther than its children's,
// so owners come out nearest first, and the walk stops once every owner is found.
void OwnerDirectory::ownersNearestFirst(const Ray& ray, int except, std::vector<OwnerEntry>& out,
                                        std::vector<NodeEntry>& heap) const {
  out.clear();
  heap.clear();
  const bool skipOne = except >= 0 && size_t(except) < ownsPieces_.size() && ownsPieces_[size_t(except)];
  const size_t wanted = leaves_.size() - (skipOne ? 1 : 0);
  if (wanted == 0) return;
  const BoxSlabs slabs(ray);
  auto later = [](const NodeEntry& a, const NodeEntry& b) { return a.t > b.t || (a.t == b.t && a.node > b.node); };
  auto push = [&](uint32_t node) {
    const Node& n = nodes_[node];
    if (n.leaf && leaves_[n.first].owner == except) return;
    float entry;
    if (!slabs.entry(n.lo, n.hi, entry)) return;
    heap.push_back({entry, node});
    std::push_heap(heap.begin(), heap.end(), later);
  };
  push(0);
  while (!heap.empty() && out.size() < wanted) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const NodeEntry e = heap.back();
    heap.pop_back();
    const Node& n = nodes_[e.node];
    if (n.leaf) {
      out.push_back({e.t, leaves_[n.first].owner});
      continue;
    }
    push(n.first);
    push(n.first + 1);
  }
}

}  // namespace pr::rt
