// Tests of the binned-SAH BVH build (raytrace/core/bvh_build.cpp): structural invariants of the
// collapsed wide tree that every query relies on, over the whole scene and over subsets
// (a PE's own triangles).
#include <doctest/doctest.h>

#include <functional>
#include <numeric>
#include <string>
#include <vector>

#include "common/util/error.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"

using pr::rt::Bvh;
using pr::rt::BvhBuildOptions;
using pr::rt::BvhNode;

namespace {

struct LaneBox {
  glm::vec3 lo, hi;
};

LaneBox lane(const BvhNode& node, int i) {
  return {{node.bounds[0][i], node.bounds[1][i], node.bounds[2][i]}, {node.bounds[3][i], node.bounds[4][i], node.bounds[5][i]}};
}

bool contains(const LaneBox& outer, glm::vec3 p) {
  return glm::all(glm::lessThanEqual(outer.lo, p)) && glm::all(glm::lessThanEqual(p, outer.hi));
}

// Walks the wide tree from the root and checks: every node is reached exactly once, each
// child's boxes lie inside the parent's box for it, leaf triangles lie inside their leaf's
// box, leaves are within the size limit and together cover Bvh::leafBlocks() exactly once, and
// empty lanes come last with empty bounds. Returns how often each scene triangle appears.
std::vector<int> checkStructure(const Bvh& bvh, size_t sceneTriangles, int maxLeafSize) {
  namespace Ref = pr::rt::BvhRef;
  const auto nodes = bvh.nodes();
  const auto blocks = bvh.leafBlocks();
  std::vector<int> nodeSeen(nodes.size(), 0), slotSeen(blocks.size(), 0), triangleSeen(sceneTriangles, 0);
  const pr::scene::Bounds all = bvh.bounds();
  std::function<void(uint32_t, const LaneBox&)> visit = [&](uint32_t ref, const LaneBox& box) {
    REQUIRE(ref != Ref::kEmpty);
    if (Ref::isLeaf(ref)) {
      CHECK(Ref::leafCount(ref) <= uint32_t(maxLeafSize));
      const uint32_t count = Ref::leafCount(ref), blockCount = pr::rt::leafBlocks(count);
      REQUIRE(Ref::leafFirst(ref) + blockCount <= blocks.size());
      for (uint32_t i = 0; i < count; ++i) {
        const uint32_t b = Ref::leafFirst(ref) + i / pr::rt::kLeafLanes;
        const int lane = int(i % pr::rt::kLeafLanes);
        if (lane == 0) slotSeen[b]++;
        const pr::rt::BvhLeafBlock& block = blocks[b];
        REQUIRE(block.triangle[lane] < sceneTriangles);
        triangleSeen[block.triangle[lane]]++;
        for (int k = 0; k < 3; ++k) CHECK(contains(box, block.vertex(k, lane)));
      }
      // Lanes past the leaf's last triangle repeat it.
      const int last = int((count - 1) % pr::rt::kLeafLanes);
      const pr::rt::BvhLeafBlock& tail = blocks[Ref::leafFirst(ref) + blockCount - 1];
      for (int lane = last + 1; lane < pr::rt::kLeafLanes; ++lane) {
        CHECK(tail.triangle[lane] == tail.triangle[last]);
        for (int k = 0; k < 3; ++k) CHECK(tail.vertex(k, lane) == tail.vertex(k, last));
      }
      return;
    }
    REQUIRE(ref < nodes.size());
    nodeSeen[ref]++;
    const BvhNode& node = nodes[ref];
    int used = 0;
    for (int i = 0; i < pr::rt::kBvhWidth; ++i) {
      if (node.child[i] == Ref::kEmpty) {
        CHECK(node.bounds[0][i] > node.bounds[3][i]);  // inverted: never hit
        continue;
      }
      CHECK(i == used);  // empty lanes only at the end
      ++used;
      const LaneBox child = lane(node, i);
      CHECK(contains(box, child.lo));
      CHECK(contains(box, child.hi));
      visit(node.child[i], child);
    }
    CHECK(used >= 2);
  };
  visit(bvh.root(), LaneBox{all.min, all.max});
  for (int seen : nodeSeen) CHECK(seen == 1);
  for (int seen : slotSeen) CHECK(seen == 1);
  return triangleSeen;
}

}  // namespace

TEST_CASE("BvhBuild: every triangle in exactly one leaf and node bounds contain their children") {
  const auto scene = pr::test::randomSoup(2000);
  for (int maxLeaf : {1, 4, 8, 16}) {
    BvhBuildOptions options;
    options.maxLeafSize = maxLeaf;
    const Bvh bvh(scene, options);
    CHECK(bvh.stats().triangles == scene.triangles.size());
    CHECK(bvh.stats().nodes == bvh.nodes().size());
    CHECK(bvh.stats().binaryNodes == 2 * bvh.stats().leaves - 1);  // a full binary tree
    CHECK(bvh.stats().nodes < bvh.stats().binaryNodes / 2);        // collapsing merges levels
    CHECK(bvh.stats().memoryBytes == bvh.nodes().size() * sizeof(BvhNode) + bvh.leafBlocks().size() * sizeof(pr::rt::BvhLeafBlock));
    const auto seen = checkStructure(bvh, scene.triangles.size(), maxLeaf);
    for (int count : seen) CHECK(count == 1);
    // The root bounds are the scene bounds.
    CHECK(bvh.bounds().min == scene.bounds.min);
    CHECK(bvh.bounds().max == scene.bounds.max);
  }
}

TEST_CASE("BvhBuild: wide nodes are mostly full (the collapse of least SAH cost)") {
  // Opening the largest child until a node was full left 3.8 children per node on average on
  // the height field; the least-cost collapse gives 5.9 (every node but the root is a child).
  // 300 triangles at one point have zero area everywhere, so every way of collapsing costs the
  // same: ties must still fill the nodes, not leave a chain of two-child ones.
  pr::scene::Scene point = pr::test::emptyScene();
  for (int i = 0; i < 300; ++i) pr::test::addTriangle(point, {1, 1, 1}, {1, 1, 1}, {1, 1, 1});
  const pr::scene::Scene scenes[] = {pr::test::heightField(160, 10.0f, 0.5f), point};
  for (const pr::scene::Scene& scene : scenes) {
    CAPTURE(scene.triangles.size());
    const Bvh bvh(scene);
    const pr::rt::BvhStats& st = bvh.stats();
    REQUIRE(st.nodes > 0);
    const double children = double(st.nodes - 1 + st.leaves) / double(st.nodes);
    CAPTURE(children);
    CHECK(children > 5.5);
    const auto seen = checkStructure(bvh, scene.triangles.size(), BvhBuildOptions{}.maxLeafSize);
    for (int count : seen) CHECK(count == 1);
  }
}

TEST_CASE("BvhBuild: a subset BVH holds exactly the subset's triangles") {
  const auto scene = pr::test::randomSoup(1000);
  std::vector<uint32_t> subset;
  for (uint32_t i = 0; i < scene.triangles.size(); i += 3) subset.push_back(i);
  const Bvh bvh(scene.positions, scene.triangles, subset);
  const auto seen = checkStructure(bvh, scene.triangles.size(), BvhBuildOptions{}.maxLeafSize);
  for (uint32_t i = 0; i < seen.size(); ++i) CHECK(seen[i] == (i % 3 == 0 ? 1 : 0));
}

TEST_CASE("BvhBuild: identical triangles (no SAH split exists) still respect the leaf size") {
  pr::scene::Scene scene = pr::test::emptyScene();
  for (int i = 0; i < 100; ++i) pr::test::addTriangle(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Bvh bvh(scene);
  const auto seen = checkStructure(bvh, scene.triangles.size(), BvhBuildOptions{}.maxLeafSize);
  for (int count : seen) CHECK(count == 1);
  CHECK(bvh.stats().maxDepth <= 6);  // median splits: 100 -> 50 -> 25 -> 13 -> 7 -> 4
}

TEST_CASE("BvhBuild: empty input gives an empty BVH that reports no hits") {
  const auto scene = pr::test::randomSoup(10);
  const Bvh bvh(scene.positions, scene.triangles, std::span<const uint32_t>{});
  CHECK(bvh.empty());
  pr::rt::Hit hit;
  CHECK_FALSE(bvh.intersect(pr::rt::Ray{{0, 0, 5}, 0.0f, {0, 0, -1}, pr::rt::kInfinity}, hit));
  CHECK_FALSE(bvh.occluded(pr::rt::Ray{{0, 0, 5}, 0.0f, {0, 0, -1}, pr::rt::kInfinity}));
}

TEST_CASE("BvhBuild: a scene that fits one leaf has a leaf as root") {
  pr::scene::Scene scene = pr::test::emptyScene();
  for (int i = 0; i < 3; ++i) pr::test::addTriangle(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});  // no split exists
  const Bvh bvh(scene);
  CHECK(pr::rt::BvhRef::isLeaf(bvh.root()));
  CHECK(bvh.nodes().empty());
  pr::rt::Hit hit;
  CHECK(bvh.intersect(pr::rt::Ray{{0.2f, 0.2f, 1.0f}, 0.0f, {0, 0, -1}, pr::rt::kInfinity}, hit));
  CHECK(hit.triangle == 0);
  const auto seen = checkStructure(bvh, scene.triangles.size(), BvhBuildOptions{}.maxLeafSize);
  for (int count : seen) CHECK(count == 1);
}

TEST_CASE("BvhBuild: degenerate triangles are counted and kept in a leaf") {
  pr::scene::Scene scene = pr::test::emptyScene();
  pr::test::addTriangle(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});  // fine
  pr::test::addTriangle(scene, {0, 0, 0}, {1, 1, 1}, {2, 2, 2});  // collinear
  pr::test::addTriangle(scene, {3, 0, 0}, {3, 0, 0}, {3, 1, 0});  // repeated vertex
  pr::test::addTriangle(scene, {5, 5, 5}, {5, 5, 5}, {5, 5, 5});  // a point
  const Bvh bvh(scene);
  CHECK(bvh.stats().degenerateTriangles == 3);
  const auto seen = checkStructure(bvh, scene.triangles.size(), BvhBuildOptions{}.maxLeafSize);
  for (int count : seen) CHECK(count == 1);
}

TEST_CASE("BvhBuild: denormal spacing and huge coordinates build a valid tree") {
  // Centres 1e-40 apart make the bin scale overflow; coordinates of 1e30 overflow box areas.
  pr::scene::Scene scene = pr::test::emptyScene();
  for (int i = 0; i < 12; ++i) {
    const float d = float(i) * 1e-40f;
    pr::test::addTriangle(scene, {d, 0, 0}, {d, 1, 0}, {d, 0, 1});
  }
  for (int i = 0; i < 12; ++i) {
    const float x = float(i + 1) * 1e30f;
    pr::test::addTriangle(scene, {x, 0, 0}, {x, 1e30f, 0}, {x, 0, 1e30f});
  }
  const Bvh bvh(scene);
  const auto seen = checkStructure(bvh, scene.triangles.size(), BvhBuildOptions{}.maxLeafSize);
  for (int count : seen) CHECK(count == 1);
}

TEST_CASE("BvhBuild: one BVH holds at most 2^27 - 1 triangles, an input error beyond") {
  // Fake counts: nothing of the size is allocated.
  auto messageOf = [](size_t n) {
    try {
      pr::rt::checkBvhLimit("scene big.gltf", n);
    } catch (const pr::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(messageOf(size_t(1) << 27) ==
        "scene big.gltf: 134217728 triangles exceed the limit of 134217727 (a BVH leaf addresses its triangles with 27 bits)");
  CHECK(messageOf((size_t(1) << 27) - 1).empty());
}
