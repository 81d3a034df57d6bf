// Building the BVH: top-down binned surface area heuristic (Wald 2007, "On fast construction
// of SAH-based bounding volume hierarchies"). Runs once per scene (image-space) or once per PE
// over that PE's own triangles (object-space, object partitioning), before any ray is traced;
// it reads only the triangles it is given and writes only the Bvh it fills. The binary tree is
// then collapsed to the wide nodes the traversal reads (bvh.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <emmintrin.h>  // SSE2: part of every x86-64 target

#include "common/util/allocator.h"
#include "common/util/error.h"
#include "common/util/limits.h"
#include "raytrace/core/bvh.h"

namespace pr::rt {
namespace {

// Below this depth the SAH decides; deeper, object-median splits halve the count each level,
// so the tree stays within the traversal stack (bvh_traverse.cpp) for any input.
constexpr int kSahDepthLimit = 32;

// An axis-aligned box as two SSE vectors (x, y, z, unused), so growing one is two instructions.
// Each lane computes what glm::min(lo, p) and glm::max(hi, p) do, NaN included: the new value
// goes first, where SSE's min and max return the second operand on NaN.
struct Box {
  __m128 lo = _mm_set1_ps(kInfinity);
  __m128 hi = _mm_set1_ps(-kInfinity);
  void extend(const glm::vec3& p) {
    const __m128 v = _mm_setr_ps(p.x, p.y, p.z, 0.0f);
    lo = _mm_min_ps(v, lo);
    hi = _mm_max_ps(v, hi);
  }
  void extend(__m128 p) {
    lo = _mm_min_ps(p, lo);
    hi = _mm_max_ps(p, hi);
  }
  void extend(const Box& b) {
    lo = _mm_min_ps(b.lo, lo);
    hi = _mm_max_ps(b.hi, hi);
  }
  glm::vec3 lower() const { return toVec3(lo); }
  glm::vec3 upper() const { return toVec3(hi); }
  // Half the surface area: the SAH only needs area ratios.
  float halfArea() const {
    const glm::vec3 l = lower(), h = upper();
    if (l.x > h.x) return 0.0f;
    const glm::vec3 d = h - l;
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
  // The same in double, at most the largest float: finite for any box of float corners.
  float cappedHalfArea() const {
    const glm::vec3 l = lower(), h = upper();
    if (l.x > h.x) return 0.0f;
    const glm::dvec3 d = glm::dvec3(h) - glm::dvec3(l);
    return float(std::min(d.x * d.y + d.y * d.z + d.z * d.x, double(std::numeric_limits<float>::max())));
  }
  static glm::vec3 toVec3(__m128 v) {
    alignas(16) float f[4];
    _mm_store_ps(f, v);
    return {f[0], f[1], f[2]};
  }
};

// One triangle during the build: its bounds, their centre (binned; lane 3 unused), its slot in
// `leafTris`.
struct PrimRef {
  Box box;
  __m128 centroid;
  uint32_t slot;
  float centre(int axis) const { return Box::toVec3(centroid)[axis]; }
};

struct Bin {
  Box box;
  uint32_t count = 0;
};

// A node of the binary SAH tree, before collapsing to kBvhWidth wide. Interior: count == 0, the first
// child follows it, `second` is the other. Leaf: triangles [first, first + count).
struct BinaryNode {
  Box box;
  uint32_t first = 0;
  uint32_t second = 0;
  uint32_t count = 0;
};

class Builder {
 public:
  Builder(const BvhBuildOptions& options, std::vector<PrimRef>& refs,
          const std::vector<BvhTriangle>& prepared, std::vector<BinaryNode>& nodes,
          std::vector<BvhTriangle>& leafTris, BvhStats& stats)
      : options_(options), refs_(refs), prepared_(prepared), nodes_(nodes), leafTris_(leafTris),
        stats_(stats), bins_(std::clamp(options.bins, 2, kMaxSahBins)) {}

  // Builds the subtree over refs_[begin, end) and returns its node index. Nodes are emitted in
  // depth-first order: the first child directly follows its parent.
  uint32_t build(uint32_t begin, uint32_t end, int depth) {
    stats_.maxDepth = std::max(stats_.maxDepth, depth);
    Box bounds, centroids;
    for (uint32_t i = begin; i < end; ++i) {
      bounds.extend(refs_[i].box);
      centroids.extend(refs_[i].centroid);
    }
    const glm::vec3 centreLo = centroids.lower(), centreHi = centroids.upper();
    const uint32_t nodeIndex = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back(BinaryNode{bounds, 0, 0, 0});
    const uint32_t count = end - begin;
    if (count == 1) return makeLeaf(nodeIndex, begin, end);

    Split split = depth < kSahDepthLimit ? findSahSplit(begin, end, bounds, centreLo, centreHi) : Split{};
    const float leafCost = options_.intersectionCost * float(leafBlocks(count));
    if (count <= uint32_t(options_.maxLeafSize) && !(split.valid && split.cost < leafCost))
      return makeLeaf(nodeIndex, begin, end);

    uint32_t mid = begin;
    if (split.valid) {
      const float lo = centreLo[split.axis];
      const float scale = float(split.bins) / (centreHi[split.axis] - centreLo[split.axis]);
      auto* first = refs_.data() + begin;
      mid = begin + uint32_t(std::partition(first, refs_.data() + end, [&](const PrimRef& r) {
                               return binIndex(r.centre(split.axis), lo, scale, split.bins) < split.bin;
                             }) - first);
    }
    if (mid == begin || mid == end) {
      // No usable SAH split (all centres equal, or below the depth limit): object median along
      // the widest centroid axis, which always makes progress.
      const glm::vec3 e = centreHi - centreLo;
      split.axis = e.x >= e.y ? (e.x >= e.z ? 0 : 2) : (e.y >= e.z ? 1 : 2);
      mid = begin + count / 2;
      std::nth_element(refs_.begin() + begin, refs_.begin() + mid, refs_.begin() + end,
                       [&](const PrimRef& a, const PrimRef& b) {
                         const float ca = a.centre(split.axis), cb = b.centre(split.axis);
                         return ca < cb || (ca == cb && a.slot < b.slot);
                       });
    }
    build(begin, mid, depth + 1);
    const uint32_t second = build(mid, end, depth + 1);
    nodes_[nodeIndex].second = second;
    return nodeIndex;
  }

 private:
  struct Split {
    bool valid = false;
    int axis = 0;
    int bin = 0;  // left side: bins [0, bin)
    int bins = 0;  // of this node's binning
    float cost = kInfinity;
  };

  // Clamped before the cast: a NaN or out-of-range float converted to int is undefined.
  static int binIndex(float c, float lo, float scale, int bins) {
    const float t = (c - lo) * scale;
    return t >= 0.0f ? (t < float(bins - 1) ? static_cast<int>(t) : bins - 1) : 0;
  }

  // SAH cost of a split into L and R (Goldsmith & Salmon 1987; MacDonald & Booth 1990):
  //   C = Ct + Ci (A(L) N(L) + A(R) N(R)) / A(node)
  // evaluated at the planes between bins, on all three axes, in one pass over refs. A node of
  // n < bins_ triangles gets n bins: the sweep over the bins then costs what binning its
  // triangles does, where 32 bins for a handful of triangles made the sweeps most of the build.
  Split findSahSplit(uint32_t begin, uint32_t end, const Box& bounds, const glm::vec3& centreLo,
                     const glm::vec3& centreHi) {
    Split best;
    const float nodeArea = bounds.halfArea();
    if (!(nodeArea > 0.0f)) return best;  // flat or point node: the median split handles it
    const int nodeBins = std::min(bins_, int(end - begin));
    // Only [0, nodeBins) of each axis is used and reset: a fresh table per call cleared all
    // 3 x 64 bins (9 KiB) for every node, most of them nodes of a few triangles.
    auto& bins = binScratch_;
    for (auto& axis : bins) std::fill_n(axis.begin(), nodeBins, Bin{});
    glm::vec3 scale(0.0f);
    for (int a = 0; a < 3; ++a) {
      const float extent = centreHi[a] - centreLo[a];
      scale[a] = extent > 0.0f ? float(nodeBins) / extent : 0.0f;
      // A denormal extent overflows the scale; (c - lo) * inf would be NaN, and casting NaN
      // to int is undefined. Such an axis cannot be split by binning anyway.
      if (!std::isfinite(scale[a])) scale[a] = 0.0f;
    }
    // binIndex() on all three axes at once: the same (c - lo) * scale, clamped to
    // [0, bins - 1] with NaN going to bin 0 (max returns its second operand, 0, on NaN).
    const __m128 lo4 = _mm_setr_ps(centreLo.x, centreLo.y, centreLo.z, 0.0f);
    const __m128 scale4 = _mm_setr_ps(scale.x, scale.y, scale.z, 0.0f);
    const __m128 last = _mm_set1_ps(float(nodeBins - 1));
    for (uint32_t i = begin; i < end; ++i) {
      const PrimRef& r = refs_[i];
      const __m128 t = _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(r.centroid, lo4), scale4), _mm_setzero_ps()), last);
      alignas(16) int32_t index[4];
      _mm_store_si128(reinterpret_cast<__m128i*>(index), _mm_cvttps_epi32(t));
      for (int a = 0; a < 3; ++a) {
        Bin& bin = bins[a][index[a]];
        bin.count++;
        bin.box.extend(r.box);
      }
    }
    std::array<float, kMaxSahBins> rightArea{};
    std::array<uint32_t, kMaxSahBins> rightCount{};
    for (int a = 0; a < 3; ++a) {
      if (scale[a] == 0.0f) continue;
      Box acc;
      uint32_t n = 0;
      for (int b = nodeBins - 1; b > 0; --b) {
        acc.extend(bins[a][b].box);
        n += bins[a][b].count;
        rightArea[b] = acc.halfArea();
        rightCount[b] = n;
      }
      acc = Box{};
      n = 0;
      for (int b = 1; b < nodeBins; ++b) {
        acc.extend(bins[a][b - 1].box);
        n += bins[a][b - 1].count;
        if (n == 0 || rightCount[b] == 0) continue;
        const float cost = options_.traversalCost +
            options_.intersectionCost * (acc.halfArea() * float(leafBlocks(n)) + rightArea[b] * float(leafBlocks(rightCount[b]))) / nodeArea;
        if (cost < best.cost) best = Split{true, a, b, nodeBins, cost};
      }
    }
    return best;
  }

  uint32_t makeLeaf(uint32_t nodeIndex, uint32_t begin, uint32_t end) {
    BinaryNode& node = nodes_[nodeIndex];
    node.first = static_cast<uint32_t>(leafTris_.size());
    node.count = end - begin;
    for (uint32_t i = begin; i < end; ++i) leafTris_.push_back(prepared_[refs_[i].slot]);
    stats_.leaves++;
    return nodeIndex;
  }

  const BvhBuildOptions& options_;
  std::vector<PrimRef>& refs_;
  const std::vector<BvhTriangle>& prepared_;
  std::vector<BinaryNode>& nodes_;
  std::vector<BvhTriangle>& leafTris_;
  BvhStats& stats_;
  int bins_;
  std::array<std::array<Bin, kMaxSahBins>, 3> binScratch_;  // findSahSplit's, per axis
};

// Which binary subtrees become the wide nodes' children: the choice of least SAH cost (Ylitie
// et al. 2017, "Efficient incoherent ray traversal on GPUs through compressed wide BVHs",
// without merging leaves), by dynamic programming over the binary tree, children before
// parents. Each binary subtree n costs, as one child of a wide node, cost[n][0]: a leaf's
// blocks, or a wide node of its own (a node visit) over its descendants spread across
// kBvhWidth slots; in j + 1 slots of its parent, cost[n][j] also considers spreading n's two
// children over them without a node for n. Opening the child with the largest area until a
// node is full (the greedy rule) left the wide nodes of the 1M-triangle terrain half empty
// (4.4 children on average), so rays visited more of them on their way down. Where ways cost
// the same (subtrees of zero area, coincident degenerate triangles, or of areas past the float
// range), the one with fewer wide nodes wins, so such nodes fill up too.
class WideCollapse {
 public:
  WideCollapse(const std::vector<BinaryNode>& binary, const BvhBuildOptions& options) : binary_(binary) {
    reserveHugePages(slots_, binary.size());  // written once, back to front
    slots_.resize(binary.size());
    // Children follow their parents (Builder::build), so a reverse sweep sees children first.
    for (size_t i = binary.size(); i-- > 0;) {
      const BinaryNode& node = binary[i];
      Slots& s = slots_[i];
      const float area = node.box.cappedHalfArea();  // no infinity: no 0 * inf among the costs
      if (node.count > 0) {
        s.way.fill(Way{options.intersectionCost * area * float(leafBlocks(node.count)), 0});
        continue;  // a leaf is always one child: split stays 0
      }
      const Slots& left = slots_[i + 1];
      const Slots& right = slots_[node.second];
      // Spread over j + 1 >= 2 slots: k + 1 of them to the left child, the rest to the right.
      // The first way stands unless another is better, so a NaN cost still gives a valid one.
      std::array<Way, kBvhWidth> spread{};
      std::array<uint8_t, kBvhWidth> spreadSplit{};
      for (int j = 1; j < kBvhWidth; ++j) {
        for (int k = 0; k < j; ++k) {
          const Way w = left.way[k] + right.way[j - 1 - k];
          if (k == 0 || w.better(spread[j])) {
            spread[j] = w;
            spreadSplit[j] = uint8_t(k + 1);
          }
        }
      }
      const Way& inside = spread[kBvhWidth - 1];
      s.way[0] = Way{options.traversalCost * area + inside.cost, inside.nodes + 1};  // a wide node of its own
      s.nodeSplit = spreadSplit[kBvhWidth - 1];
      for (int j = 1; j < kBvhWidth; ++j) {
        // At most j + 1 slots: the best of fewer slots, or its children spread over all of them.
        s.way[j] = s.way[j - 1];
        s.split[j] = s.split[j - 1];
        if (!s.way[j].better(spread[j])) {
          s.way[j] = spread[j];
          s.split[j] = spreadSplit[j];
        }
      }
    }
  }

  // The binary subtrees that are the children of the wide node made for interior node n.
  int children(uint32_t n, std::array<uint32_t, kBvhWidth>& out) const {
    int count = 0;
    const uint8_t k = slots_[n].nodeSplit;
    gather(n + 1, k - 1, out, count);
    gather(binary_[n].second, kBvhWidth - 1 - k, out, count);
    return count;
  }

 private:
  // A way to represent a subtree: its SAH cost, and its wide nodes, which decide between ways
  // of equal cost (fewer nodes: fuller ones).
  struct Way {
    float cost = 0.0f;
    uint32_t nodes = 0;
    bool better(const Way& o) const { return cost < o.cost || (cost == o.cost && nodes < o.nodes); }
    Way operator+(const Way& o) const { return {cost + o.cost, nodes + o.nodes}; }
  };
  struct Slots {
    std::array<Way, kBvhWidth> way{};  // [j]: the best in at most j + 1 slots
    // [j]: 0 when n is one child in j + 1 slots, else the slots its left child takes.
    std::array<uint8_t, kBvhWidth> split{};
    uint8_t nodeSplit = 0;  // slots the left child takes in n's own wide node
  };

  void gather(uint32_t n, int j, std::array<uint32_t, kBvhWidth>& out, int& count) const {
    const uint8_t k = slots_[n].split[j];
    if (k == 0) {
      out[count++] = n;
      return;
    }
    gather(n + 1, k - 1, out, count);
    gather(binary_[n].second, j - k, out, count);
  }

  const std::vector<BinaryNode>& binary_;
  std::vector<Slots> slots_;
};

// Collapses the binary subtree at `index` into wide nodes appended to `wide`, its leaves'
// triangles (in leafTris) packed into blocks appended to `blocks`, and returns its reference.
uint32_t collapse(const std::vector<BinaryNode>& binary, const WideCollapse& plan, uint32_t index,
                  const std::vector<BvhTriangle>& leafTris, std::vector<BvhNode>& wide, std::vector<BvhLeafBlock>& blocks) {
  const BinaryNode& node = binary[index];
  if (node.count > 0) {
    const auto first = static_cast<uint32_t>(blocks.size());
    for (uint32_t i = 0; i < node.count; i += kLeafLanes)
      blocks.push_back(packLeafBlock(leafTris.data() + node.first + i, std::min<uint32_t>(node.count - i, kLeafLanes)));
    return BvhRef::leaf(first, node.count);
  }
  std::array<uint32_t, kBvhWidth> kids{};
  const int n = plan.children(index, kids);
  const auto wideIndex = static_cast<uint32_t>(wide.size());
  wide.emplace_back();
  for (int lane = 0; lane < kBvhWidth; ++lane) {
    // Empty lanes get inverted bounds: the slab test's entry is +inf there, so they never hit.
    const Box box = lane < n ? binary[kids[lane]].box : Box{};
    for (int a = 0; a < 3; ++a) {
      wide[wideIndex].bounds[a][lane] = box.lower()[a];
      wide[wideIndex].bounds[3 + a][lane] = box.upper()[a];
    }
    wide[wideIndex].child[lane] = BvhRef::kEmpty;
  }
  for (int lane = 0; lane < n; ++lane) {
    const uint32_t ref = collapse(binary, plan, kids[lane], leafTris, wide, blocks);  // may reallocate `wide`
    wide[wideIndex].child[lane] = ref;
  }
  return wideIndex;
}

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// A triangle whose vertices are collinear (or coincide, or are not finite) has no area and
// must never be hit. Rounding in the edge functions could still report a hit on a collinear
// triangle, so it is stored with all three vertices equal: then every edge function is exactly
// 0 (a*b - b*a), det = 0 and the test rejects it (triangle.h).
BvhTriangle prepareTriangle(std::span<const glm::vec3> positions, const scene::Triangle& tri,
                            uint32_t index, bool& degenerate) {
  const glm::vec3 p0 = positions[tri.v[0]], p1 = positions[tri.v[1]], p2 = positions[tri.v[2]];
  const glm::dvec3 n = glm::cross(glm::dvec3(p1) - glm::dvec3(p0), glm::dvec3(p2) - glm::dvec3(p0));
  degenerate = !(finite(p0) && finite(p1) && finite(p2)) || (n.x == 0.0 && n.y == 0.0 && n.z == 0.0);
  if (!degenerate) return BvhTriangle{p0, p1, p2, index};
  const glm::vec3 anchor = finite(p0) ? p0 : finite(p1) ? p1 : finite(p2) ? p2 : glm::vec3(0.0f);
  return BvhTriangle{anchor, anchor, anchor, index};
}

}  // namespace

BvhLeafBlock packLeafBlock(const BvhTriangle* tri, uint32_t count) {
  PR_CHECK(count >= 1 && count <= uint32_t(kLeafLanes), "packLeafBlock: " + std::to_string(count) + " triangles");
  BvhLeafBlock block;
  for (int lane = 0; lane < kLeafLanes; ++lane) {
    const BvhTriangle& one = tri[std::min<uint32_t>(uint32_t(lane), count - 1)];
    const glm::vec3* vertices[3] = {&one.p0, &one.p1, &one.p2};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) block.p[k][a][lane] = (*vertices[k])[a];
    block.triangle[lane] = one.triangle;
  }
  return block;
}

Bvh::Bvh(const scene::Scene& scene, const BvhBuildOptions& options) {
  std::vector<uint32_t> all(scene.triangles.size());
  for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  build(scene.positions, scene.triangles, all, options);
  if (!alpha_) alpha_ = AlphaTest::forScene(scene);
}

void checkBvhLimit(std::string_view where, size_t triangles) {
  checkCountLimit(where, "triangles", triangles, BvhRef::kMaxTriangles - 1,
                  "a BVH leaf addresses its triangles with 27 bits");
}

Bvh::Bvh(std::span<const glm::vec3> positions, std::span<const scene::Triangle> triangles,
         std::span<const uint32_t> subset, const BvhBuildOptions& options) {
  build(positions, triangles, subset, options);
}

void Bvh::build(std::span<const glm::vec3> positions, std::span<const scene::Triangle> triangles,
                std::span<const uint32_t> subset, const BvhBuildOptions& options) {
  PR_CHECK(options.maxLeafSize >= 1 && uint32_t(options.maxLeafSize) <= BvhRef::kMaxLeafSize,
           "maxLeafSize " + std::to_string(options.maxLeafSize) + " outside [1, 16]");
  PR_CHECK(subset.size() < BvhRef::kMaxTriangles, "too many triangles for one BVH: " + std::to_string(subset.size()));
  stats_ = BvhStats{};
  alpha_ = options.alpha;
  nodes_.clear();
  leafBlocks_.clear();
  root_ = BvhRef::kEmpty;
  bounds_ = scene::Bounds{};
  magnitude_ = 0.0f;
  if (subset.empty()) return;

  // The build writes each of its arrays once, front to back: 2 MiB pages spare most page faults,
  // and appending (no resize) spares writing zeros first; a build of a large scene is bound by
  // its first writes to fresh memory, not by the SAH.
  std::vector<BvhTriangle> prepared;
  reserveHugePages(prepared, subset.size());
  std::vector<PrimRef> refs;
  reserveHugePages(refs, subset.size());
  for (size_t i = 0; i < subset.size(); ++i) {
    const uint32_t index = subset[i];
    PR_CHECK(index < triangles.size(), "triangle index " + std::to_string(index) + " out of range");
    const scene::Triangle& tri = triangles[index];
    for (uint32_t v : tri.v)
      PR_CHECK(v < positions.size(), "triangle " + std::to_string(index) + " names a missing vertex");
    bool degenerate = false;
    prepared.push_back(prepareTriangle(positions, tri, index, degenerate));
    stats_.degenerateTriangles += degenerate ? 1 : 0;
    PrimRef& ref = refs.emplace_back();
    ref.box.extend(prepared[i].p0);
    ref.box.extend(prepared[i].p1);
    ref.box.extend(prepared[i].p2);
    const __m128 half = _mm_set1_ps(0.5f);  // halved first: no overflow near FLT_MAX
    ref.centroid = _mm_add_ps(_mm_mul_ps(half, ref.box.lo), _mm_mul_ps(half, ref.box.hi));
    ref.slot = static_cast<uint32_t>(i);
    const glm::vec3 m = glm::max(glm::abs(ref.box.lower()), glm::abs(ref.box.upper()));
    magnitude_ = std::max({magnitude_, m.x, m.y, m.z});
  }

  std::vector<BinaryNode> binary;
  reserveHugePages(binary, 2 * subset.size() / std::max(1, options.maxLeafSize / 2) + 1);
  std::vector<BvhTriangle> leafTris;
  reserveHugePages(leafTris, subset.size());
  Builder builder(options, refs, prepared, binary, leafTris, stats_);
  builder.build(0, static_cast<uint32_t>(refs.size()), 0);
  // The traversal stack holds at most kBvhWidth - 1 entries per level (bvh_traverse.cpp).
  PR_CHECK(stats_.maxDepth <= 60, "BVH deeper than the traversal stack: " + std::to_string(stats_.maxDepth));
  refs = {};
  prepared = {};

  reserveHugePages(nodes_, binary.size() / 2 + 1);
  reserveHugePages(leafBlocks_, stats_.leaves + leafTris.size() / kLeafLanes);
  // The reserves are upper bounds and stay: what is never written costs no memory, while
  // shrinking would copy both arrays into fresh memory once more.
  {
    const WideCollapse plan(binary, options);
    root_ = collapse(binary, plan, 0, leafTris, nodes_, leafBlocks_);
  }
  bounds_.extend(binary[0].box.lower());
  bounds_.extend(binary[0].box.upper());

  stats_.binaryNodes = binary.size();
  stats_.nodes = nodes_.size();
  stats_.triangles = leafTris.size();
  stats_.memoryBytes = nodes_.size() * sizeof(BvhNode) + leafBlocks_.size() * sizeof(BvhLeafBlock);
}

scene::Bounds Bvh::bounds() const { return bounds_; }

}  // namespace pr::rt
