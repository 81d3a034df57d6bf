// Tests of the BVH queries (raytrace/core/bvh_traverse.cpp): closest hit equals a brute-force
// loop over all triangles (same t, same triangle, same barycentrics), whatever the tree shape
// or partitioning; any hit agrees with closest hit; ties and bad rays are handled.
#include <doctest/doctest.h>
#include <cstddef>
#include <cstring>

#include <cmath>
#include <random>
#include <vector>

#include "common/parallel/wire.h"
#include "common/util/cpu_features.h"
#include "common/util/error.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/core/triangle.h"

using pr::rt::Bvh;
using pr::rt::BvhBuildOptions;
using pr::rt::Hit;
using pr::rt::Ray;

namespace {

// The reference: every triangle tested, the deterministic order of Hit::closerThan.
Hit bruteForce(const pr::scene::Scene& scene, const Ray& ray) {
  Hit best;
  best.t = ray.tMax;
  const pr::rt::RayShear shear = pr::rt::makeRayShear(ray);
  for (uint32_t i = 0; i < scene.triangles.size(); ++i) {
    const auto& tri = scene.triangles[i];
    pr::rt::TriangleHit th;
    if (!pr::rt::intersectTriangle(shear, scene.positions[tri.v[0]], scene.positions[tri.v[1]],
                                   scene.positions[tri.v[2]], ray.tMin, ray.tMax, th))
      continue;
    const Hit candidate{th.t, i, th.u, th.v};
    if (candidate.closerThan(best)) best = candidate;
  }
  if (!best.valid()) best.t = pr::rt::kInfinity;
  return best;
}

Hit query(const Bvh& bvh, const Ray& ray) {
  Hit hit;
  if (!bvh.intersect(ray, hit)) return Hit{};
  return hit;
}

// Rays from a cube of side 4 around the soup, in random directions, with random intervals.
std::vector<Ray> randomRays(int count, float scale, glm::vec3 centre, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-2.0f, 2.0f), unit(0.0f, 1.0f);
  std::vector<Ray> rays;
  for (int i = 0; i < count; ++i) {
    Ray r;
    r.origin = centre + scale * glm::vec3(pos(rng), pos(rng), pos(rng));
    // Aim half of the rays at the soup so most of them hit something.
    r.direction = i % 2 ? pr::test::randomDirection(rng)
                        : glm::normalize(centre + scale * 0.5f * glm::vec3(pos(rng), pos(rng), pos(rng)) - r.origin);
    if (i % 5 == 0) {
      r.tMin = scale * 2.0f * unit(rng);
      r.tMax = r.tMin + scale * 3.0f * unit(rng);
    }
    rays.push_back(r);
  }
  return rays;
}

void checkSame(const Hit& got, const Hit& want) {
  CHECK(got.triangle == want.triangle);
  if (want.valid()) {
    CHECK(got.t == want.t);
    CHECK(got.u == want.u);
    CHECK(got.v == want.v);
  }
}

}  // namespace

TEST_CASE("BvhTraverse: closest hit equals brute force on a random soup") {
  const auto scene = pr::test::randomSoup(1200);
  const Bvh bvh(scene);
  int hits = 0;
  for (const Ray& ray : randomRays(3000, 1.0f, glm::vec3(0.0f), 11)) {
    const Hit want = bruteForce(scene, ray);
    checkSame(query(bvh, ray), want);
    hits += want.valid();
  }
  CHECK(hits > 1000);  // the comparison is not vacuous
}

TEST_CASE("BvhTraverse: results do not depend on tree shape or on partitioning the triangles") {
  const auto scene = pr::test::randomSoup(1000, 1.0f, glm::vec3(0.0f), 3);
  BvhBuildOptions small, large;
  small.maxLeafSize = 1;
  small.bins = 16;
  large.maxLeafSize = 8;
  const Bvh a(scene, small), b(scene, large);
  // Three PEs' own BVHs over interleaved thirds, as object partitioning builds them; the
  // originator keeps the closest of their answers.
  std::vector<std::vector<uint32_t>> parts(3);
  for (uint32_t i = 0; i < scene.triangles.size(); ++i) parts[(i * 7) % 3].push_back(i);
  std::vector<Bvh> owners;
  for (const auto& part : parts) owners.emplace_back(scene.positions, scene.triangles, part);
  for (const Ray& ray : randomRays(2000, 1.0f, glm::vec3(0.0f), 5)) {
    const Hit want = bruteForce(scene, ray);
    checkSame(query(a, ray), want);
    checkSame(query(b, ray), want);
    Hit merged;
    for (const Bvh& owner : owners) {
      const Hit h = query(owner, ray);
      if (h.valid() && h.closerThan(merged)) merged = h;
    }
    checkSame(merged, want);
  }
}

TEST_CASE("BvhTraverse: any hit agrees with closest hit, including the interval ends") {
  const auto scene = pr::test::randomSoup(2000, 1.0f, glm::vec3(0.0f), 9);
  const Bvh bvh(scene);
  int checked = 0;
  for (Ray ray : randomRays(3000, 1.0f, glm::vec3(0.0f), 13)) {
    Hit hit;
    const bool found = bvh.intersect(ray, hit);
    CHECK(bvh.occluded(ray) == found);
    if (found) {
      // A shadow ray ending exactly at the hit sees it (closed interval); one ending just
      // before it sees it only if another triangle lies in between, which closest hit denies.
      ray.tMax = hit.t;
      CHECK(bvh.occluded(ray));
      ray.tMax = std::nextafter(hit.t, 0.0f);
      Hit nearer;
      CHECK(bvh.occluded(ray) == bvh.intersect(ray, nearer));
      CHECK_FALSE(bvh.intersect(ray, nearer));
      ++checked;
    }
  }
  CHECK(checked > 500);
}

TEST_CASE("BvhTraverse: equal t goes to the lower triangle index in any leaf order") {
  // Eight copies of one triangle, stored in different leaves and in reverse subset order.
  pr::scene::Scene scene = pr::test::emptyScene();
  for (int i = 0; i < 8; ++i) pr::test::addTriangle(scene, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
  pr::test::addTriangle(scene, {-1, -1, 1}, {1, -1, 1}, {0, 1, 1});  // farther along the ray
  std::vector<uint32_t> subset = {8, 7, 6, 5, 4, 3};
  BvhBuildOptions options;
  options.maxLeafSize = 1;
  const Bvh all(scene, options), part(scene.positions, scene.triangles, subset, options);
  const Ray ray{{0.1f, -0.2f, -3.0f}, 0.0f, {0, 0, 1}, pr::rt::kInfinity};
  CHECK(query(all, ray).triangle == 0);
  CHECK(query(part, ray).triangle == 3);
  CHECK(query(all, ray).t == doctest::Approx(3.0f));
}

TEST_CASE("BvhTraverse: closest hit equals brute force at scene scales from 1e-4 to 1e5") {
  for (float scale : {1e-4f, 1e-2f, 1.0f, 1e3f, 1e5f}) {
    CAPTURE(scale);
    // Off-centre, so coordinates are large compared with the triangles at large scales.
    const glm::vec3 centre = scale * glm::vec3(3.0f, -2.0f, 1.0f);
    const auto scene = pr::test::randomSoup(500, scale, centre, 17);
    const Bvh bvh(scene);
    int hits = 0;
    for (const Ray& ray : randomRays(800, scale, centre, 19)) {
      const Hit want = bruteForce(scene, ray);
      const Hit got = query(bvh, ray);
      checkSame(got, want);
      if (got.valid()) CHECK(std::isfinite(got.t));
      hits += want.valid();
    }
    CHECK(hits > 200);
  }
}

TEST_CASE("BvhTraverse: unusable rays (zero or NaN direction, empty interval) hit nothing") {
  const auto scene = pr::test::randomSoup(200);
  const Bvh bvh(scene);
  Hit hit;
  const float nan = std::nanf("");
  CHECK_FALSE(bvh.intersect(Ray{{0, 0, 0}, 0.0f, {0, 0, 0}, pr::rt::kInfinity}, hit));
  CHECK_FALSE(bvh.intersect(Ray{{0, 0, 0}, 0.0f, {nan, 0, 1}, pr::rt::kInfinity}, hit));
  CHECK_FALSE(bvh.intersect(Ray{{nan, 0, 0}, 0.0f, {0, 0, 1}, pr::rt::kInfinity}, hit));
  CHECK_FALSE(bvh.intersect(Ray{{0, 0, -5}, 2.0f, {0, 0, 1}, 1.0f}, hit));
  CHECK_FALSE(bvh.occluded(Ray{{0, 0, 0}, 0.0f, {0, 0, 0}, pr::rt::kInfinity}));
  CHECK_FALSE(hit.valid());
}

namespace {
// Sets the slab test's lanes for one scope, and puts back what was there.
struct ScopedSlabLanes {
  explicit ScopedSlabLanes(int lanes) : saved(pr::rt::bvhSlabLanes()) { pr::rt::setBvhSlabLanes(lanes); }
  ~ScopedSlabLanes() { pr::rt::setBvhSlabLanes(saved); }
  int saved;
};
}  // namespace

TEST_CASE("BvhTraverse: the 4-lane and 8-lane slab tests give brute force's hits, and each other's, bit for bit") {
  // A closed box of grid triangles: rays along the axes and in the grid planes make the 0 * inf
  // slab distances, and the random rays the general case.
  const auto soup = pr::test::randomSoup(1500, 1.0f, glm::vec3(0.0f), 23);
  const auto box = pr::test::closedBox(glm::vec3(-1.0f), glm::vec3(1.0f), 6);
  std::vector<Ray> axisRays;
  for (int k = -6; k <= 6; ++k)
    for (int axis = 0; axis < 3; ++axis) {
      const float c = float(k) / 6.0f;  // on the grid lines and between them
      Ray r;
      r.origin = glm::vec3(0.0f);
      r.origin[(axis + 1) % 3] = c;
      r.origin[(axis + 2) % 3] = 0.5f * c;
      r.direction = glm::vec3(0.0f);
      r.direction[axis] = k % 2 ? 1.0f : -1.0f;
      axisRays.push_back(r);
    }
  std::vector<int> widths = {4};
  if (pr::hasAvx2()) widths.push_back(8);
  else MESSAGE("this processor has no AVX2: only the 4-lane slab test runs");
  for (const pr::scene::Scene* scene : {&soup, &box}) {
    const Bvh bvh(*scene);
    std::vector<Ray> rays = randomRays(1500, 1.0f, glm::vec3(0.0f), 29);
    rays.insert(rays.end(), axisRays.begin(), axisRays.end());
    std::vector<std::vector<Hit>> hits(widths.size());
    for (size_t w = 0; w < widths.size(); ++w) {
      const ScopedSlabLanes lanes(widths[w]);
      CHECK(pr::rt::bvhSlabLanes() == widths[w]);
      int found = 0;
      for (const Ray& ray : rays) {
        const Hit want = bruteForce(*scene, ray);
        hits[w].push_back(query(bvh, ray));
        checkSame(hits[w].back(), want);
        CHECK(bvh.occluded(ray) == want.valid());
        found += want.valid();
      }
      CHECK(found > 500);
    }
    for (size_t i = 0; i < rays.size() && widths.size() == 2; ++i) {
      CHECK(hits[0][i].triangle == hits[1][i].triangle);
      CHECK(hits[0][i].t == hits[1][i].t);
    }
  }
}

TEST_CASE("BvhTraverse: a slab test of other than 4 or 8 lanes is an input error") {
  CHECK_THROWS_AS(pr::rt::setBvhSlabLanes(3), pr::InputError);
  CHECK_THROWS_AS(pr::rt::setBvhSlabLanes(16), pr::InputError);
  if (!pr::hasAvx2()) CHECK_THROWS_AS(pr::rt::setBvhSlabLanes(8), pr::InputError);
}

TEST_CASE("BvhTraverse: a BVH decoded from its encoding answers every query as the one built, and short bytes are refused") {
  const auto scene = pr::test::randomSoup(900, 1.0f, glm::vec3(0.0f), 5);
  const Bvh built(scene);
  pr::par::Bytes bytes;
  pr::par::WireWriter w(bytes);
  built.encode(w);
  pr::par::WireReader r(bytes);
  const Bvh decoded = Bvh::decode(r, nullptr);
  CHECK(r.remaining() == 0);
  CHECK(decoded.root() == built.root());
  CHECK(decoded.nodes().size() == built.nodes().size());
  CHECK(decoded.stats().memoryBytes == built.stats().memoryBytes);
  int hits = 0;
  for (const Ray& ray : randomRays(2000, 1.0f, glm::vec3(0.0f), 17)) {
    const Hit want = query(built, ray);
    checkSame(query(decoded, ray), want);
    CHECK(decoded.occluded(ray) == built.occluded(ray));
    hits += want.valid();
  }
  CHECK(hits > 500);
  // References that would send a traversal out of the arrays or round in a cycle are refused.
  const std::size_t root = 0;
  const std::size_t firstChild = sizeof(uint32_t) + sizeof(pr::scene::Bounds) + sizeof(float) + sizeof(pr::rt::BvhStats) +
                                 sizeof(uint64_t) + offsetof(pr::rt::BvhNode, child);
  REQUIRE(built.nodes().size() > 1);
  REQUIRE(!pr::rt::BvhRef::isLeaf(built.root()));
  const auto decodesWith = [&](std::size_t at, uint32_t ref) {
    pr::par::Bytes bad = bytes;
    std::memcpy(bad.data() + at, &ref, sizeof ref);
    pr::par::WireReader reader(bad);
    (void)Bvh::decode(reader, nullptr);
  };
  CHECK_NOTHROW(decodesWith(firstChild, built.nodes()[0].child[0]));
  CHECK_THROWS_AS(decodesWith(root, uint32_t(built.nodes().size())), pr::par::WireError);
  CHECK_THROWS_AS(decodesWith(firstChild, 0u), pr::par::WireError);  // node 0 naming itself
  CHECK_THROWS_AS(decodesWith(firstChild, pr::rt::BvhRef::leaf(uint32_t(built.leafBlocks().size()), 1)), pr::par::WireError);
  bytes.resize(bytes.size() - 1);
  pr::par::WireReader shortReader(bytes);
  CHECK_THROWS_AS(Bvh::decode(shortReader, nullptr), pr::par::WireError);
}
