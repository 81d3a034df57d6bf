// The bounding volume hierarchy every ray tracer queries: built with the binned surface area
// heuristic over any subset of the scene's triangles (image-space: all of them; object-space
// and object partitioning: one PE's own triangles only), stored as 8-wide nodes (one AVX2 slab
// test checks eight boxes) in depth-first order with the leaf triangles copied next to them.
// Queries: closest hit and any hit (shadow).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "raytrace/core/alpha_test.h"
#include "raytrace/core/ray.h"

namespace pr::par {
class WireWriter;
class WireReader;
}  // namespace pr::par

namespace pr::rt {

// Children per node: one AVX2 slab test of eight lanes, or two SSE tests of four where the
// processor has no AVX2 (bvh_traverse_lanes.inc). Measured on the 1M-triangle terrain
// (bench_rays, leaves in blocks of four): against 4-wide nodes, 25-45% more rays per second
// with either test, for 59 instead of 56 bytes per triangle (both with the earlier greedy
// collapse; the least-cost one below takes 8-wide nodes to 54).
inline constexpr int kBvhWidth = 8;

// Leaf triangles tested at once (triangle4.h): one SSE lane each. The SAH counts a leaf's cost
// in such blocks, so a leaf of four costs what a leaf of one does.
inline constexpr int kLeafLanes = 4;
inline constexpr uint32_t leafBlocks(uint32_t triangles) { return (triangles + kLeafLanes - 1) / kLeafLanes; }

// One node of the 8-wide BVH, 256 bytes (four cache lines): the bounds of its children, one
// SIMD lane each (bounds[0..2] = min x, y, z; bounds[3..5] = max x, y, z), and the children's
// references (see BvhRef). The binned-SAH build makes a binary tree first and collapses it
// into the wide nodes of least SAH cost (bvh_build.cpp; Ylitie et al. 2017), 5.9 children per
// node on the 1M-triangle terrain; one wide slab test then replaces about three levels of a
// balanced binary tree (up to seven of an unbalanced one), and a ray's chain of dependent node
// loads gets that much shorter.
struct alignas(64) BvhNode {
  float bounds[6][kBvhWidth];
  uint32_t child[kBvhWidth];
  uint32_t pad[kBvhWidth];
};
static_assert(sizeof(BvhNode) == 32 * kBvhWidth, "BvhNode must stay 32 bytes per lane");

// Lanes of the slab test the queries run: 8 (AVX2) where the processor has it, else 4 (SSE2).
// Both give bit-identical hits; tests and benchmarks set 4 to run the other kernel (setting 8
// on a processor without AVX2 throws pr::InputError). Process-wide; set it while no query runs.
int bvhSlabLanes();
void setBvhSlabLanes(int lanes);

// A reference to a child: an interior node index, a leaf (bit 31; bits 27-30 = triangle count
// - 1; bits 0-26 = its first block in Bvh::leafBlocks()), or empty (all bits set, empty bounds).
namespace BvhRef {
inline constexpr uint32_t kEmpty = 0xffffffffu;
inline constexpr uint32_t kLeafBit = 0x80000000u;
inline constexpr int kCountShift = 27;
inline constexpr uint32_t kMaxLeafSize = 16;
inline constexpr uint32_t kMaxTriangles = 1u << kCountShift;
inline bool isLeaf(uint32_t ref) { return (ref & kLeafBit) != 0; }
inline uint32_t leafFirst(uint32_t ref) { return ref & (kMaxTriangles - 1); }
inline uint32_t leafCount(uint32_t ref) { return ((ref >> kCountShift) & 15u) + 1; }
inline uint32_t leaf(uint32_t first, uint32_t count) { return kLeafBit | ((count - 1) << kCountShift) | first; }
}  // namespace BvhRef

// Throws pr::InputError "<where>: N triangles exceed the limit of ..." when one BVH would hold
// more triangles than a leaf reference can address (BvhRef::kMaxTriangles - 1, 27 bits).
// Called where a ray-traced render starts, on the whole scene (every BVH a partition builds
// holds a subset of it).
void checkBvhLimit(std::string_view where, size_t triangles);

// A leaf triangle as the build prepares it: its world-space vertices and its scene triangle
// index, which hit records report.
struct BvhTriangle {
  glm::vec3 p0, p1, p2;
  uint32_t triangle;
};

// Four of a leaf's triangles, vertex coordinates by lane (p[vertex][axis][lane]), so the leaf
// test (triangle4.h) loads each coordinate of four triangles with one aligned read and needs
// no transposes. A leaf of n triangles is ceil(n / 4) consecutive blocks; lanes past the last
// triangle repeat it (the test masks them off). 160 bytes, as four BvhTriangles.
struct alignas(16) BvhLeafBlock {
  float p[3][3][kLeafLanes];
  uint32_t triangle[kLeafLanes];
  glm::vec3 vertex(int k, int lane) const { return {p[k][0][lane], p[k][1][lane], p[k][2][lane]}; }
};
static_assert(sizeof(BvhLeafBlock) == 40 * kLeafLanes, "a leaf block must stay as small as its triangles");

// Packs tri[0, count) (1 <= count <= kLeafLanes) into one block.
BvhLeafBlock packLeafBlock(const BvhTriangle* tri, uint32_t count);

// The most SAH bins per axis a build uses (BvhBuildOptions::bins is clamped to [2, this]): on
// the 1M-triangle terrain 64 gave 2-4% more rays per second than 32 for 5% more build time,
// 128 and 256 nothing more for 20% and 70% more.
inline constexpr int kMaxSahBins = 64;

struct BvhBuildOptions {
  int bins = kMaxSahBins;  // SAH bins per axis (Wald 2007, "On fast construction of SAH-based BVHs")
  int maxLeafSize = 4;    // a leaf never holds more triangles than this (1..16)
  float traversalCost = 1.0f;     // SAH cost of visiting a node, relative to one triangle test
  float intersectionCost = 1.0f;  // SAH cost of one watertight triangle test
  // Alpha-cut surfaces (alpha_test.h): hits where it fails do not count, in both queries. The
  // scene constructor makes it for a scene that needs one when none is given.
  std::shared_ptr<const AlphaTest> alpha;
};

// Counts of one build, for benchmarks and reports (Category/what naming in the run record).
struct BvhStats {
  size_t binaryNodes = 0;  // nodes of the binary SAH tree before collapsing
  size_t nodes = 0;        // wide nodes
  size_t leaves = 0;
  size_t triangles = 0;
  size_t degenerateTriangles = 0;  // stored, but made unhittable (see bvh_build.cpp)
  int maxDepth = 0;                // of the binary tree
  size_t memoryBytes = 0;          // nodes + leaf blocks
};

class Bvh {
 public:
  Bvh() = default;
  // All triangles of the scene.
  explicit Bvh(const scene::Scene& scene, const BvhBuildOptions& options = {});
  // Only the listed scene triangles (indices into triangles); hits report these indices.
  Bvh(std::span<const glm::vec3> positions, std::span<const scene::Triangle> triangles,
      std::span<const uint32_t> subset, const BvhBuildOptions& options = {});

  // Closest hit with t in [ray.tMin, ray.tMax]; equal t goes to the lower triangle index.
  // Returns false (and leaves `hit` untouched) when nothing is hit. Thread-safe (read-only).
  bool intersect(const Ray& ray, Hit& hit) const;
  // True when any triangle is hit with t in [ray.tMin, ray.tMax] (shadow rays); stops at the
  // first one found. Agrees with intersect(): occluded(r) == intersect(r, h).
  bool occluded(const Ray& ray) const;

  bool empty() const { return root_ == BvhRef::kEmpty; }
  // The root reference: a node index, or a leaf when everything fits in one.
  uint32_t root() const { return root_; }
  std::span<const BvhNode> nodes() const { return nodes_; }
  std::span<const BvhLeafBlock> leafBlocks() const { return leafBlocks_; }
  const BvhStats& stats() const { return stats_; }
  scene::Bounds bounds() const;

  // The BVH as bytes, for a broadcast between ranks (bvh_wire.cpp): everything but the alpha
  // test, which the receiver makes from its own copy of the scene (what the build would have
  // used). decode throws par::WireError on bytes that are not one BVH.
  void encode(par::WireWriter& w) const;
  static Bvh decode(par::WireReader& r, std::shared_ptr<const AlphaTest> alpha);
  // The size of that encoding, without making it.
  std::size_t encodedBytes() const;

 private:
  void build(std::span<const glm::vec3> positions, std::span<const scene::Triangle> triangles,
             std::span<const uint32_t> subset, const BvhBuildOptions& options);

  uint32_t root_ = BvhRef::kEmpty;
  scene::Bounds bounds_;
  std::vector<BvhNode> nodes_;
  std::vector<BvhLeafBlock> leafBlocks_;
  BvhStats stats_;
  float magnitude_ = 0.0f;  // largest |coordinate| of any vertex, for the traversal slack
  std::shared_ptr<const AlphaTest> alpha_;
};

}  // namespace pr::rt
