// Tests of the object-space kd split (raytrace/partition/voxel_split.cpp): cells tile space and
// hold every triangle that overlaps them, splits balance triangle counts rather than volumes,
// walks give contiguous ordered spans (also for rays lying in split planes), and the first hit
// found voxel by voxel is bit-identical to the full BVH's.
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include "common/util/error.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/voxel_split.h"

using pr::rt::Bvh;
using pr::rt::Hit;
using pr::rt::Ray;
using pr::rt::VoxelSpan;
using pr::rt::VoxelSplit;

namespace {

bool overlaps(const pr::scene::Bounds& a, const pr::scene::Bounds& b, float margin) {
  for (int k = 0; k < 3; ++k)
    if (a.max[k] < b.min[k] - margin || a.min[k] > b.max[k] + margin) return false;
  return true;
}

pr::scene::Bounds triangleBounds(const pr::scene::Scene& s, uint32_t t) {
  pr::scene::Bounds b;
  for (uint32_t v : s.triangles[t].v) b.extend(s.positions[v]);
  return b;
}

// The object-space rule, here without messages: visit the voxels in order, query each voxel's
// own BVH up to the end of its span, stop at the first hit.
Hit voxelByVoxel(const VoxelSplit& split, const std::vector<Bvh>& bvhs, const Ray& ray) {
  Hit result;
  split.walk(ray, [&](const VoxelSpan& span) {
    Ray clipped = ray;
    clipped.tMax = std::min(ray.tMax, span.tExit);
    Hit h;
    if (bvhs[span.voxel].intersect(clipped, h)) {
      result = h;
      return false;
    }
    return true;
  });
  return result;
}

// Test ray i: an even one from the eye towards a random point of the plane z = 0, an odd one
// from a random point in a random direction (u's draws, scaled per axis, taken in order).
Ray eyeOrRandomRay(int i, glm::vec3 eye, std::mt19937& rng, std::uniform_real_distribution<float>& u,
                   glm::vec3 originScale = glm::vec3(1.0f), glm::vec2 targetScale = glm::vec2(1.0f)) {
  Ray ray;
  if (i % 2 == 0) {
    const float x = u(rng), y = u(rng);
    ray.origin = eye;
    ray.direction = glm::normalize(glm::vec3(x * targetScale.x, y * targetScale.y, 0.0f) - eye);
  } else {
    const float x = u(rng), y = u(rng), z = u(rng);
    ray.origin = glm::vec3(x, y, z) * originScale;
    ray.direction = pr::test::randomDirection(rng);
  }
  return ray;
}

std::vector<Bvh> voxelBvhs(const pr::scene::Scene& s, const VoxelSplit& split) {
  std::vector<Bvh> bvhs;
  for (int v = 0; v < split.voxels(); ++v) bvhs.emplace_back(s.positions, s.triangles, split.triangles(v));
  return bvhs;
}

// The finite split-plane coordinates per axis, read off the cells.
std::vector<std::set<float>> splitPlanes(const VoxelSplit& split) {
  std::vector<std::set<float>> planes(3);
  for (int v = 0; v < split.voxels(); ++v)
    for (int a = 0; a < 3; ++a) {
      if (std::isfinite(split.cell(v).min[a])) planes[a].insert(split.cell(v).min[a]);
      if (std::isfinite(split.cell(v).max[a])) planes[a].insert(split.cell(v).max[a]);
    }
  return planes;
}

}  // namespace

TEST_CASE("VoxelSplit: cells tile space and hold every triangle overlapping them") {
  const pr::scene::Scene s = pr::test::randomSoup(600, 1.0f, glm::vec3(0.0f), 3);
  const float margin = pr::rt::partitionMargin(s, glm::vec3(0.0f, 0.0f, 5.0f));
  const VoxelSplit split(s, {7, margin});
  REQUIRE(split.voxels() == 7);
  for (int v = 0; v < split.voxels(); ++v) {
    const auto tris = split.triangles(v);
    CHECK(std::is_sorted(tris.begin(), tris.end()));
    const std::set<uint32_t> held(tris.begin(), tris.end());
    for (uint32_t t = 0; t < s.triangles.size(); ++t)
      CHECK(held.count(t) == (overlaps(triangleBounds(s, t), split.cell(v), margin) ? 1u : 0u));
  }
  // Every point lies in exactly one cell, the one voxelAt names (upper side on a plane).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  for (int i = 0; i < 500; ++i) {
    const glm::vec3 p(u(rng), u(rng), u(rng));
    int inside = 0;
    for (int v = 0; v < split.voxels(); ++v) {
      const auto& c = split.cell(v);
      if (p.x >= c.min.x && p.x < c.max.x && p.y >= c.min.y && p.y < c.max.y && p.z >= c.min.z && p.z < c.max.z) {
        ++inside;
        CHECK(split.voxelAt(p) == v);
      }
    }
    CHECK(inside == 1);
  }
}

TEST_CASE("VoxelSplit: splits balance triangle counts, not volumes") {
  // 900 small triangles packed into x in [0, 1] and 100 spread over x in [1, 10], in a thin
  // slab along x: an equal-size split at x = 5 would leave one voxel 95% of the work.
  pr::scene::Scene s = pr::test::emptyScene();
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const float x = i < 900 ? u(rng) : 1.0f + 9.0f * u(rng);
    const glm::vec3 a(x, 0.05f * u(rng), 0.05f * u(rng));  // a thin slab: x is the axis to cut
    pr::test::addTriangle(s, a, a + glm::vec3(0.01f, 0.0f, 0.0f), a + glm::vec3(0.0f, 0.01f, 0.0f));
  }
  const VoxelSplit split(s, {2, pr::rt::partitionMargin(s, glm::vec3(0.0f))});
  const size_t a = split.triangles(0).size(), b = split.triangles(1).size();
  CHECK(a + b >= 1000);
  CHECK(a + b <= 1020);  // few straddlers of one plane
  CHECK(std::max(a, b) <= 530);
  // The plane sits inside the dense cluster, far from the middle of the scene.
  const auto planes = splitPlanes(split);
  REQUIRE(planes[0].size() == 1);
  CHECK(*planes[0].begin() < 1.0f);

  // k·P voxels: the greedy owners hold about the same geometry.
  const VoxelSplit fine(s, {12, pr::rt::partitionMargin(s, glm::vec3(0.0f))});
  const std::vector<int> owners = pr::rt::assignVoxelOwners(fine, 4);
  std::vector<size_t> held(4, 0);
  for (int v = 0; v < 12; ++v) held[owners[v]] += fine.triangles(v).size();
  CHECK(*std::max_element(held.begin(), held.end()) <= 1.2 * (*std::min_element(held.begin(), held.end())) + 10);
  const std::vector<int> same = pr::rt::assignVoxelOwners(split, 2);
  CHECK(same == std::vector<int>{0, 1});
}

TEST_CASE("VoxelSplit: spans are contiguous, ordered and lie in their voxels") {
  const pr::scene::Scene s = pr::test::randomSoup(400, 1.0f, glm::vec3(0.0f), 8);
  const VoxelSplit split(s, {8, pr::rt::partitionMargin(s, glm::vec3(0.0f))});
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (int i = 0; i < 300; ++i) {
    Ray ray;
    ray.origin = glm::vec3(u(rng), u(rng), u(rng));
    ray.direction = pr::test::randomDirection(rng);
    ray.tMin = i % 3 == 0 ? 0.5f : 0.0f;
    ray.tMax = i % 2 == 0 ? pr::rt::kInfinity : 3.0f;
    const std::vector<VoxelSpan> spans = split.spans(ray);
    REQUIRE(!spans.empty());
    CHECK(spans.front().tEnter == ray.tMin);
    CHECK(spans.back().tExit == ray.tMax);
    std::set<uint32_t> seen;
    for (size_t k = 0; k < spans.size(); ++k) {
      CHECK(spans[k].tEnter < spans[k].tExit);
      if (k > 0) CHECK(spans[k].tEnter == spans[k - 1].tExit);
      CHECK(seen.insert(spans[k].voxel).second);  // kd cells are convex: visited once
      const float tEnd = std::isfinite(spans[k].tExit) ? spans[k].tExit : spans[k].tEnter + 100.0f;
      const float tMid = 0.5f * (spans[k].tEnter + tEnd);
      CHECK(split.voxelAt(ray.origin + tMid * ray.direction) == int(spans[k].voxel));
    }
  }
}

TEST_CASE("VoxelSplit: voxel by voxel first hits equal the full BVH bit for bit") {
  const pr::scene::Scene s = pr::test::randomSoup(800, 1.0f, glm::vec3(0.0f), 21);
  const glm::vec3 eye(0.3f, -0.2f, 4.0f);
  const VoxelSplit split(s, {6, pr::rt::partitionMargin(s, eye)});
  const Bvh full(s);
  const std::vector<Bvh> bvhs = voxelBvhs(s, split);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.2f, 1.2f);
  int hits = 0;
  for (int i = 0; i < 600; ++i) {
    const Ray ray = eyeOrRandomRay(i, eye, rng, u);
    Hit expected;
    const bool hit = full.intersect(ray, expected);
    const Hit got = voxelByVoxel(split, bvhs, ray);
    REQUIRE(got.valid() == hit);
    if (!hit) continue;
    ++hits;
    CHECK(got.triangle == expected.triangle);
    CHECK(got.t == expected.t);
    CHECK(got.u == expected.u);
    CHECK(got.v == expected.v);
  }
  CHECK(hits > 200);
}

TEST_CASE("VoxelSplit: a voxel's content boxes are reached wherever it has a hit, and not across empty space") {
  // Every span in which the voxel's own BVH has a hit must reach its content (else object-space
  // would skip the owner of the hit); a ray through the gap between two far clusters reaches
  // neither's content although it crosses their voxels.
  pr::scene::Scene s = pr::test::randomSoup(400, 0.5f, glm::vec3(-3.0f, 0.0f, 0.0f), 5);
  pr::test::appendTriangles(s, pr::test::randomSoup(400, 0.5f, glm::vec3(3.0f, 0.0f, 0.0f), 6));
  const glm::vec3 eye(0.0f, 0.5f, 6.0f);
  const VoxelSplit split(s, {8, pr::rt::partitionMargin(s, eye)});
  const std::vector<Bvh> bvhs = voxelBvhs(s, split);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f);
  int hitSpans = 0;
  for (int i = 0; i < 800; ++i) {
    const Ray ray = eyeOrRandomRay(i, eye, rng, u, glm::vec3(1.0f, 0.3f, 0.3f), glm::vec2(1.0f, 0.2f));
    const pr::rt::RaySlabs slabs(ray);
    split.walk(ray, [&](const VoxelSpan& span) {
      Ray clipped = ray;
      clipped.tMin = span.tEnter;
      clipped.tMax = span.tExit;
      Hit h;
      if (bvhs[span.voxel].intersect(clipped, h)) {
        ++hitSpans;
        CHECK(split.reachesContent(span.voxel, slabs, span.tEnter, span.tExit));
      }
      return true;
    });
  }
  CHECK(hitSpans > 50);
  // Straight down through the middle, between the clusters (x = +-3, radius about 0.5).
  Ray gap;
  gap.origin = glm::vec3(0.0f, 5.0f, 0.0f);
  gap.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  const pr::rt::RaySlabs slabs(gap);
  int crossed = 0;
  split.walk(gap, [&](const VoxelSpan& span) {
    ++crossed;
    CHECK_FALSE(split.reachesContent(span.voxel, slabs, span.tEnter, span.tExit));
    return true;
  });
  CHECK(crossed > 0);
}

TEST_CASE("VoxelSplit: held-only content leaves out the replicated triangles") {
  // Two clusters; the triangles of the one at x = +3 are replicated. A ray through that cluster
  // reaches its voxel's content, but not the part only the owner holds.
  pr::scene::Scene s = pr::test::randomSoup(200, 0.5f, glm::vec3(-3.0f, 0.0f, 0.0f), 5);
  const auto firstReplicated = uint32_t(s.triangles.size());
  pr::test::appendTriangles(s, pr::test::randomSoup(200, 0.5f, glm::vec3(3.0f, 0.0f, 0.0f), 6));
  std::vector<uint32_t> replicated;
  for (auto t = firstReplicated; t < s.triangles.size(); ++t) replicated.push_back(t);
  const VoxelSplit split(s, {2, 0.0f, {}, replicated});
  for (float x : {-3.0f, 3.0f}) {
    Ray ray;
    ray.origin = glm::vec3(x, 5.0f, 0.0f);
    ray.direction = glm::vec3(0.0f, -1.0f, 0.0f);
    const pr::rt::RaySlabs slabs(ray);
    const uint32_t voxel = uint32_t(split.voxelAt(glm::vec3(x, 0.0f, 0.0f)));
    CHECK(split.reachesContent(voxel, slabs, ray.tMin, ray.tMax));
    CHECK(split.reachesHeldOnly(voxel, slabs, ray.tMin, ray.tMax) == (x < 0.0f));
  }
}

TEST_CASE("VoxelSplit: with work points the cuts balance work, and dealing counts the triangles held too") {
  // A cluster of 600 triangles around x = -3 with a tenth of the work, and a wall of two
  // triangles at x = +3 with the rest, spread over its face.
  pr::scene::Scene s = pr::test::randomSoup(600, 0.5f, glm::vec3(-3.0f, 0.0f, 0.0f), 8);
  pr::test::addTriangle(s, {3, -2, -2}, {3, 2, -2}, {3, 2, 2});
  pr::test::addTriangle(s, {3, -2, -2}, {3, 2, 2}, {3, -2, 2});
  std::vector<pr::rt::WorkPoint> work;
  for (int i = 0; i < 90; ++i) work.push_back({glm::vec3(3.0f, -1.9f + 0.04f * float(i), 0.5f * float(i % 7) - 1.5f), 1.0f});
  for (int i = 0; i < 10; ++i) work.push_back({glm::vec3(-3.0f + 0.01f * float(i), 0.05f * float(i), 0.0f), 1.0f});
  const VoxelSplit split(s, {4, 0.0f, work});
  for (float triangleWork : {0.0f, 1.0f}) {
    CAPTURE(triangleWork);
    // Equal work per voxel: the cluster's 600 triangles fall in two of them, the wall's two
    // triangles in the other two.
    for (int v = 0; v < 4; ++v) CHECK(split.work(v) == doctest::Approx(25.0));
    REQUIRE(split.triangles(0).size() == 2);
    REQUIRE(split.triangles(1).size() > 300);
    REQUIRE(split.triangles(2).size() > 300);
    REQUIRE(split.triangles(3).size() == 2);
    // Longest first: by work alone the four are equal and dealt in turn (0, 1, 0, 1); with a
    // triangle's work the cluster's voxels go first, one to each PE, and the wall's two voxels
    // to the lighter PE (PE 1, holding 321 triangles against 361).
    const std::vector<int> owners = pr::rt::assignVoxelOwners(split, 2, triangleWork);
    CHECK(owners == (triangleWork == 0.0f ? std::vector<int>{0, 1, 0, 1} : std::vector<int>{1, 0, 1, 1}));
  }
}

TEST_CASE("VoxelSplit: rays lying in split planes find the same hits as the full BVH") {
  // A closed box tessellated into a grid: its vertices, edges and the split planes coincide,
  // so rays along a plane pass exactly through shared edges and triangles lying in it.
  const pr::scene::Scene s = pr::test::closedBox(glm::vec3(-1.0f), glm::vec3(1.0f), 4);
  const VoxelSplit split(s, {8, pr::rt::partitionMargin(s, glm::vec3(0.0f))});
  const Bvh full(s);
  const std::vector<Bvh> bvhs = voxelBvhs(s, split);
  const auto planes = splitPlanes(split);
  int tested = 0;
  for (int a = 0; a < 3; ++a)
    for (float plane : planes[a]) {
      for (int k = 0; k < 16; ++k) {
        // Origin in the plane, direction in the plane (component a exactly 0).
        Ray ray;
        ray.origin = glm::vec3(0.1f * (k % 4) - 0.15f, 0.1f * (k / 4) - 0.15f, 0.05f * k - 0.4f);
        ray.origin[a] = plane;
        glm::vec3 d(std::cos(0.4f * k), std::sin(0.4f * k), std::cos(0.9f * k));
        d[a] = 0.0f;
        ray.direction = d;
        for (const VoxelSpan& span : split.spans(ray)) {
          // The whole ray stays on the upper side of its own plane.
          CHECK(split.cell(span.voxel).min[a] <= plane);
          CHECK(split.cell(span.voxel).max[a] > plane);
        }
        Hit expected;
        REQUIRE(full.intersect(ray, expected));  // inside a closed box every ray hits
        const Hit got = voxelByVoxel(split, bvhs, ray);
        CHECK(got.triangle == expected.triangle);
        CHECK(got.t == expected.t);
        ++tested;
      }
    }
  CHECK(tested >= 16);
  // A ray from a point on a plane, leaving it: it visits only the side it points to.
  Ray leave;
  leave.origin = glm::vec3(0.0f);
  leave.origin.x = *planes[0].begin();
  leave.direction = glm::vec3(-1.0f, 0.0f, 0.0f);
  for (const VoxelSpan& span : split.spans(leave)) CHECK(split.cell(span.voxel).max.x <= leave.origin.x);
}

TEST_CASE("VoxelSplit: one voxel holds the whole scene, bad counts are input errors") {
  const pr::scene::Scene s = pr::test::randomSoup(50);
  const VoxelSplit one(s, {1, 0.0f});
  CHECK(one.voxels() == 1);
  CHECK(one.triangles(0).size() == 50);
  CHECK(one.spans(Ray{}).size() == 1);
  CHECK_THROWS_AS(VoxelSplit(s, {0, 0.0f}), pr::InputError);
  CHECK_THROWS_AS(VoxelSplit(s, {5000, 0.0f}), pr::InputError);
  // An empty scene still splits space (every span misses).
  const VoxelSplit empty(pr::test::emptyScene(), {4, 0.0f});
  CHECK(empty.voxels() == 4);
  CHECK(empty.storedTriangles() == 0);
}

TEST_CASE("VoxelSplit: a split decoded from its encoding walks, holds and tests content as the one made, and bad bytes are refused") {
  // Two clusters, one replicated, with work points: every part of the split is non-trivial.
  pr::scene::Scene s = pr::test::randomSoup(300, 0.5f, glm::vec3(-2.0f, 0.0f, 0.0f), 3);
  const auto firstReplicated = uint32_t(s.triangles.size());
  pr::test::appendTriangles(s, pr::test::randomSoup(300, 0.5f, glm::vec3(2.0f, 0.0f, 0.0f), 4));
  std::vector<uint32_t> replicated;
  for (auto t = firstReplicated; t < s.triangles.size(); ++t) replicated.push_back(t);
  std::vector<pr::rt::WorkPoint> work;
  for (int i = 0; i < 64; ++i) work.push_back({glm::vec3(-2.0f + 0.06f * float(i), 0.0f, 0.0f), 1.0f + float(i % 3)});
  const glm::vec3 eye(0.0f, 0.5f, 5.0f);
  const VoxelSplit made(s, {8, pr::rt::partitionMargin(s, eye), work, replicated});
  pr::par::Bytes bytes;
  pr::par::WireWriter w(bytes);
  made.encode(w);
  pr::par::WireReader r(bytes);
  const VoxelSplit decoded = VoxelSplit::decode(r);
  CHECK(r.remaining() == 0);
  REQUIRE(decoded.voxels() == made.voxels());
  CHECK(decoded.margin() == made.margin());
  CHECK(decoded.treeBytes() == made.treeBytes());
  for (int v = 0; v < made.voxels(); ++v) {
    CHECK(std::ranges::equal(decoded.triangles(v), made.triangles(v)));
    CHECK(decoded.work(v) == made.work(v));
  }
  CHECK(decoded.hasWork());
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  int reached = 0;
  for (int i = 0; i < 400; ++i) {
    const Ray ray = eyeOrRandomRay(i, eye, rng, u);
    const std::vector<VoxelSpan> a = made.spans(ray), b = decoded.spans(ray);
    REQUIRE(a.size() == b.size());
    const pr::rt::RaySlabs slabs(ray);
    for (size_t k = 0; k < a.size(); ++k) {
      CHECK(a[k].voxel == b[k].voxel);
      CHECK(a[k].tEnter == b[k].tEnter);
      CHECK(a[k].tExit == b[k].tExit);
      const bool content = made.reachesContent(a[k].voxel, slabs, a[k].tEnter, a[k].tExit);
      CHECK(decoded.reachesContent(b[k].voxel, slabs, b[k].tEnter, b[k].tExit) == content);
      CHECK(decoded.reachesHeldOnly(b[k].voxel, slabs, b[k].tEnter, b[k].tExit) ==
            made.reachesHeldOnly(a[k].voxel, slabs, a[k].tEnter, a[k].tExit));
      reached += content;
    }
  }
  CHECK(reached > 30);
  pr::par::Bytes truncated(bytes.begin(), bytes.end() - 1);
  pr::par::WireReader shortReader(truncated);
  CHECK_THROWS_AS(VoxelSplit::decode(shortReader), pr::par::WireError);
  pr::par::Bytes empty;
  pr::par::WireReader emptyReader(empty);
  CHECK_THROWS_AS(VoxelSplit::decode(emptyReader), pr::par::WireError);
}
