// Tests of the left-balanced kd-tree (photonmap/kd_tree.h): k-nearest and range search equal a
// brute-force search (random sets, duplicates, points on split planes, k beyond the map, k = 0,
// an empty map), every photon is stored once and found again, the heap invariants hold, and the
// parallel build gives the same tree bit for bit for every P.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

#include "common/parallel/runtime.h"
#include "photonmap/kd_tree.h"
#include "photonmap/photon_test_support.h"

using pr::pm::KdTree;
using pr::pm::NearestPhotons;
using pr::pm::Photon;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The squared distances of the k nearest accepted photons within maxRadius, ascending.
template <class Accept>
std::vector<float> bruteNearest(const std::vector<Photon>& photons, const glm::vec3& x, int k, float maxRadius,
                                Accept accept) {
  std::vector<float> d;
  if (k <= 0 || !(maxRadius >= 0.0f)) return d;
  for (const Photon& p : photons) {
    const float d2 = pr::pm::detail::distSq(p.position, x);
    if (d2 <= maxRadius * maxRadius && accept(p)) d.push_back(d2);
  }
  std::sort(d.begin(), d.end());
  if (d.size() > static_cast<std::size_t>(k)) d.resize(static_cast<std::size_t>(k));
  return d;
}

std::vector<float> treeNearest(const KdTree& tree, const glm::vec3& x, int k, float maxRadius, NearestPhotons& out) {
  tree.nearest(x, k, maxRadius, out);
  std::vector<float> d;
  for (const auto& nb : out.neighbors) d.push_back(nb.distSq);
  std::sort(d.begin(), d.end());
  return d;
}

// Compares the tree's k-nearest answer at x with brute force: the same distances (ties may pick
// different photons at the k-th distance, never a different distance), a max-heap, and the
// search disc: the k-th distance when k were found, the maximum radius otherwise.
void checkAgainstBruteForce(const std::vector<Photon>& input, const KdTree& tree, const glm::vec3& x, int k,
                            float maxRadius) {
  NearestPhotons out;
  const std::vector<float> expected = bruteNearest(input, x, k, maxRadius, [](const Photon&) { return true; });
  const std::vector<float> got = treeNearest(tree, x, k, maxRadius, out);
  REQUIRE(got == expected);
  if (!out.empty()) {
    CHECK(out.neighbors.front().distSq == expected.back());  // max-heap: the farthest first
    for (const auto& nb : out.neighbors)
      CHECK(pr::pm::detail::distSq(tree.photons()[nb.index].position, x) == nb.distSq);
  }
  if (k > 0 && maxRadius >= 0.0f && expected.size() == static_cast<std::size_t>(k)) CHECK(out.radiusSq == expected.back());
  else if (k > 0 && maxRadius >= 0.0f) CHECK(out.radiusSq == maxRadius * maxRadius);
  else CHECK(out.radiusSq == 0.0f);
}

// The split invariant of every node: its left subtree lies at or below its split coordinate, its
// right subtree at or above (ties may go either way). Returns the number of nodes visited.
void checkSplitInvariant(const KdTree& tree) {
  const auto nodes = tree.photons();
  const std::size_t n = nodes.size();
  for (std::size_t i = 0; i < n; ++i) {
    const int axis = nodes[i].splitAxis();
    REQUIRE(axis < 3);
    const float split = nodes[i].position[axis];
    std::vector<std::size_t> todo;
    if (2 * i + 1 < n) todo.push_back(2 * i + 1);
    bool ok = true;
    while (!todo.empty()) {
      const std::size_t j = todo.back();
      todo.pop_back();
      ok = ok && nodes[j].position[axis] <= split;
      for (std::size_t c : {2 * j + 1, 2 * j + 2})
        if (c < n) todo.push_back(c);
    }
    if (2 * i + 2 < n) todo.push_back(2 * i + 2);
    while (!todo.empty()) {
      const std::size_t j = todo.back();
      todo.pop_back();
      ok = ok && nodes[j].position[axis] >= split;
      for (std::size_t c : {2 * j + 1, 2 * j + 2})
        if (c < n) todo.push_back(c);
    }
    REQUIRE(ok);
  }
}

bool samePositions(std::vector<Photon> a, std::span<const Photon> b) {
  auto less = [](const Photon& p, const Photon& q) {
    if (p.position.x != q.position.x) return p.position.x < q.position.x;
    if (p.position.y != q.position.y) return p.position.y < q.position.y;
    return p.position.z < q.position.z;
  };
  std::vector<Photon> c(b.begin(), b.end());
  std::sort(a.begin(), a.end(), less);
  std::sort(c.begin(), c.end(), less);
  if (a.size() != c.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].position != c[i].position) return false;
  return true;
}

}  // namespace

TEST_CASE("KdTree: k-nearest equals brute force on random sets") {
  pr::test::TestRng rng(3);
  for (std::size_t n : {1u, 2u, 3u, 7u, 8u, 100u, 1023u, 1024u, 1025u, 3000u}) {
    CAPTURE(n);
    const std::vector<Photon> input = pr::test::randomPhotons(n, 100 + n);
    const KdTree tree = KdTree::build(input);
    REQUIRE(tree.size() == n);
    for (int q = 0; q < 40; ++q) {
      const glm::vec3 x = rng.inBox(-1.2f, 1.2f);
      for (int k : {1, 5, 50, static_cast<int>(n) + 10})
        for (float r : {0.05f, 0.3f, kInf}) {
          CAPTURE(k);
          CAPTURE(r);
          checkAgainstBruteForce(input, tree, x, k, r);
        }
    }
  }
}

TEST_CASE("KdTree: duplicate points and points exactly on split planes") {
  // A 6 x 6 x 6 integer grid, each point three times: every split plane passes through many
  // points, and every point has two twins at distance 0.
  std::vector<Photon> input;
  for (int rep = 0; rep < 3; ++rep)
    for (int x = 0; x < 6; ++x)
      for (int y = 0; y < 6; ++y)
        for (int z = 0; z < 6; ++z) input.push_back(Photon::make(glm::vec3(x, y, z), glm::vec3(1.0f), {0, 0, 1}));
  const KdTree tree = KdTree::build(input);
  REQUIRE(tree.size() == input.size());
  checkSplitInvariant(tree);
  pr::test::TestRng rng(5);
  for (int q = 0; q < 200; ++q) {
    // Queries on grid points, on half-integers (equidistant from many points) and at random.
    glm::vec3 x = q % 3 == 0   ? glm::vec3(static_cast<float>(q % 6), static_cast<float>((q / 6) % 6), 2.0f)
                  : q % 3 == 1 ? glm::vec3(2.5f, static_cast<float>(q % 6) + 0.5f, 1.5f)
                               : rng.inBox(-0.5f, 5.5f);
    for (int k : {1, 3, 4, 27, 50, 1000})
      for (float r : {0.0f, 0.5f, 1.0f, 1.5f, kInf}) {
        CAPTURE(k);
        CAPTURE(r);
        checkAgainstBruteForce(input, tree, x, k, r);
      }
  }
  // All photons in one point: a degenerate tree whose every split plane holds every photon.
  const std::vector<Photon> same(77, Photon::make({1, 1, 1}, glm::vec3(1.0f), {0, 0, 1}));
  const KdTree point = KdTree::build(same);
  checkAgainstBruteForce(same, point, {1, 1, 1}, 10, 0.0f);
  checkAgainstBruteForce(same, point, {1, 1, 1}, 100, 0.0f);
  checkAgainstBruteForce(same, point, {1, 1, 1.5f}, 100, 0.4f);
}

TEST_CASE("KdTree: k = 0, an empty map and a negative or NaN radius find nothing") {
  NearestPhotons out;
  out.neighbors.push_back({1.0f, 0});
  const KdTree empty = KdTree::build({});
  CHECK(empty.empty());
  empty.nearest({0, 0, 0}, 10, 1.0f, out);
  CHECK(out.empty());
  CHECK(out.radiusSq == 1.0f);  // the disc searched, empty
  CHECK(empty.countWithin({0, 0, 0}, kInf) == 0);
  const std::vector<Photon> input = pr::test::randomPhotons(100, 9);
  const KdTree tree = KdTree::build(input);
  tree.nearest({0, 0, 0}, 0, 1.0f, out);
  CHECK(out.empty());
  CHECK(out.radiusSq == 0.0f);
  tree.nearest({0, 0, 0}, 5, -1.0f, out);
  CHECK(out.empty());
  tree.nearest({0, 0, 0}, 5, std::numeric_limits<float>::quiet_NaN(), out);
  CHECK(out.empty());
  CHECK(tree.countWithin({0, 0, 0}, -1.0f) == 0);
}

TEST_CASE("KdTree: every stored photon is found again") {
  // Every size up to 300 (all shapes of a last level) and a large random set: the heap holds
  // the input exactly (no photon lost or duplicated), a k = 1 query at each photon's position
  // finds a photon at distance 0, and range counts equal brute force.
  for (std::size_t n = 1; n <= 300; ++n) {
    const std::vector<Photon> input = pr::test::randomPhotons(n, n);
    const KdTree tree = KdTree::build(input);
    REQUIRE(samePositions(input, tree.photons()));
    NearestPhotons out;
    for (const Photon& p : input) {
      tree.nearest(p.position, 1, 1e-3f, out);
      REQUIRE(out.size() == 1);
      REQUIRE(out.neighbors[0].distSq == 0.0f);
    }
  }
  const std::vector<Photon> input = pr::test::randomPhotons(50000, 77);
  const KdTree tree = KdTree::build(input);
  REQUIRE(samePositions(input, tree.photons()));
  checkSplitInvariant(KdTree::build(pr::test::randomPhotons(2000, 78)));
  std::vector<int> found(tree.size(), 0);
  NearestPhotons out;
  for (const Photon& p : tree.photons()) {
    tree.nearest(p.position, 1, 0.0f, out);
    REQUIRE(out.size() == 1);
    REQUIRE(out.neighbors[0].distSq == 0.0f);
    ++found[out.neighbors[0].index];
  }
  // Random points are distinct, so each query found the photon itself.
  CHECK(std::count(found.begin(), found.end(), 1) == static_cast<long>(tree.size()));
  pr::test::TestRng rng(4);
  for (int q = 0; q < 50; ++q) {
    const glm::vec3 x = rng.inBox(-1.0f, 1.0f);
    const float r = rng.uniform(0.0f, 0.3f);
    std::size_t brute = 0;
    for (const Photon& p : input) brute += pr::pm::detail::distSq(p.position, x) <= r * r ? 1 : 0;
    CHECK(tree.countWithin(x, r) == brute);
  }
  CHECK(tree.countWithin({0, 0, 0}, kInf) == input.size());
}

TEST_CASE("KdTree: the predicate filters photons during the search") {
  // Every third photon is a caustic photon; a search that accepts only those equals brute force
  // over them alone (the k found are the k nearest accepted, not k nearest then filtered).
  std::vector<Photon> input = pr::test::randomPhotons(2000, 21);
  for (std::size_t i = 0; i < input.size(); i += 3) input[i].setKind(pr::pm::PhotonMapKind::Caustic);
  const KdTree tree = KdTree::build(input);
  auto caustic = [](const Photon& p) { return p.kind() == pr::pm::PhotonMapKind::Caustic; };
  pr::test::TestRng rng(22);
  NearestPhotons out;
  for (int q = 0; q < 100; ++q) {
    const glm::vec3 x = rng.inBox(-1.0f, 1.0f);
    tree.nearest(x, 20, 0.5f, caustic, out);
    std::vector<float> got;
    for (const auto& nb : out.neighbors) {
      CHECK(caustic(tree.photons()[nb.index]));
      got.push_back(nb.distSq);
    }
    std::sort(got.begin(), got.end());
    CHECK(got == bruteNearest(input, x, 20, 0.5f, caustic));
  }
}

TEST_CASE("KdTree: the parallel build gives the same tree bit for bit for every P") {
  // Above the parallel threshold (2^15 photons), with duplicates so ties are exercised.
  std::vector<Photon> input = pr::test::randomPhotons(60000, 31);
  for (std::size_t i = 0; i < 5000; ++i) input.push_back(input[i * 7]);
  const KdTree serial = KdTree::build(input);
  for (int pes : {1, 2, 3, 5}) {
    CAPTURE(pes);
    pr::par::Runtime runtime(pes);
    const KdTree parallel = KdTree::build(input, runtime);
    REQUIRE(parallel.size() == serial.size());
    CHECK(std::memcmp(parallel.photons().data(), serial.photons().data(), serial.bytes()) == 0);
  }
}
