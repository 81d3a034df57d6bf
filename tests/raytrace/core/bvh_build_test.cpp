// Tests of the binned-SAH BVH build (raytrace/core/bvh_build.cpp): structural invariants that
// every query relies on, over the whole scene and over subsets (a PE's own triangles).
#include <doctest/doctest.h>

#include <functional>
#include <numeric>
#include <vector>

#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"

using pr::rt::Bvh;
using pr::rt::BvhBuildOptions;
using pr::rt::BvhNode;

namespace {

bool contains(const BvhNode& outer, glm::vec3 p) {
  return glm::all(glm::lessThanEqual(outer.boundsMin, p)) && glm::all(glm::lessThanEqual(p, outer.boundsMax));
}

// Walks the tree from the root and checks: every node is reached exactly once, children lie
// inside their parent, leaf triangles inside their leaf, leaves within the size limit and
// together covering Bvh::triangles() exactly once. Returns how often each scene triangle
// index appears in a leaf.
std::vector<int> checkStructure(const Bvh& bvh, size_t sceneTriangles, int maxLeafSize) {
  const auto nodes = bvh.nodes();
  const auto tris = bvh.triangles();
  std::vector<int> nodeSeen(nodes.size(), 0), slotSeen(tris.size(), 0), triangleSeen(sceneTriangles, 0);
  std::function<void(uint32_t)> visit = [&](uint32_t index) {
    REQUIRE(index < nodes.size());
    nodeSeen[index]++;
    const BvhNode& node = nodes[index];
    if (node.isLeaf()) {
      CHECK(node.count <= maxLeafSize);
      REQUIRE(node.offset + node.count <= tris.size());
      for (uint32_t i = node.offset; i < node.offset + node.count; ++i) {
        slotSeen[i]++;
        REQUIRE(tris[i].triangle < sceneTriangles);
        triangleSeen[tris[i].triangle]++;
        CHECK(contains(node, tris[i].p0));
        CHECK(contains(node, tris[i].p1));
        CHECK(contains(node, tris[i].p2));
      }
      return;
    }
    const uint32_t first = index + 1, second = node.offset;
    REQUIRE(second > first);
    for (uint32_t child : {first, second}) {
      REQUIRE(child < nodes.size());
      CHECK(contains(node, nodes[child].boundsMin));
      CHECK(contains(node, nodes[child].boundsMax));
      visit(child);
    }
  };
  visit(0);
  for (int seen : nodeSeen) CHECK(seen == 1);
  for (int seen : slotSeen) CHECK(seen == 1);
  return triangleSeen;
}

}  // namespace

TEST_CASE("BvhBuild: every triangle in exactly one leaf and node bounds contain their children") {
  const auto scene = pr::test::randomSoup(3000);
  for (int maxLeaf : {1, 4, 8}) {
    BvhBuildOptions options;
    options.maxLeafSize = maxLeaf;
    const Bvh bvh(scene, options);
    CHECK(bvh.stats().triangles == scene.triangles.size());
    CHECK(bvh.stats().nodes == bvh.nodes().size());
    CHECK(bvh.stats().nodes == 2 * bvh.stats().leaves - 1);  // a full binary tree
    CHECK(bvh.stats().memoryBytes == bvh.nodes().size() * 32 + bvh.triangles().size() * sizeof(pr::rt::BvhTriangle));
    const auto seen = checkStructure(bvh, scene.triangles.size(), maxLeaf);
    for (int count : seen) CHECK(count == 1);
    // The root bounds are the scene bounds.
    CHECK(bvh.bounds().min == scene.bounds.min);
    CHECK(bvh.bounds().max == scene.bounds.max);
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
  CHECK(bvh.stats().maxDepth <= 8);  // median splits: ceil(log2(100 / 4)) + 1 levels
}

TEST_CASE("BvhBuild: empty input gives an empty BVH that reports no hits") {
  const auto scene = pr::test::randomSoup(10);
  const Bvh bvh(scene.positions, scene.triangles, std::span<const uint32_t>{});
  CHECK(bvh.empty());
  pr::rt::Hit hit;
  CHECK_FALSE(bvh.intersect(pr::rt::Ray{{0, 0, 5}, 0.0f, {0, 0, -1}, pr::rt::kInfinity}, hit));
  CHECK_FALSE(bvh.occluded(pr::rt::Ray{{0, 0, 5}, 0.0f, {0, 0, -1}, pr::rt::kInfinity}));
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
