// Tests of the watertight ray-triangle test (raytrace/core/triangle.h), alone and through the
// BVH: rays exactly through shared edges and vertices never miss, grazing rays give no NaN,
// degenerate triangles are never hit.
#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <random>
#include <vector>

#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/core/triangle.h"
#include "raytrace/core/triangle4.h"

using pr::rt::Bvh;
using pr::rt::Hit;
using pr::rt::Ray;

namespace {

// Points on the mesh's edges: every vertex and eight points along every triangle edge.
std::vector<glm::vec3> edgePoints(const pr::scene::Scene& scene) {
  std::vector<glm::vec3> points;
  for (const auto& tri : scene.triangles)
    for (int e = 0; e < 3; ++e) {
      const glm::vec3 a = scene.positions[tri.v[e]], b = scene.positions[tri.v[(e + 1) % 3]];
      for (int k = 0; k < 8; ++k) points.push_back(a + (b - a) * (float(k) / 8.0f));
    }
  return points;
}

}  // namespace

TEST_CASE("Triangle: a single hit reports t and barycentrics of p = (1-u-v) p0 + u p1 + v p2") {
  const glm::vec3 p0(0, 0, 0), p1(4, 0, 0), p2(0, 2, 0);
  const Ray ray{{1, 0.5f, 3}, 0.0f, {0, 0, -1}, pr::rt::kInfinity};
  pr::rt::TriangleHit h;
  REQUIRE(pr::rt::intersectTriangle(pr::rt::makeRayShear(ray), p0, p1, p2, 0.0f, 10.0f, h));
  CHECK(h.t == doctest::Approx(3.0f));
  CHECK(h.u == doctest::Approx(0.25f));
  CHECK(h.v == doctest::Approx(0.25f));
  // Back face (the other winding) hits too: nothing is culled.
  REQUIRE(pr::rt::intersectTriangle(pr::rt::makeRayShear(ray), p0, p2, p1, 0.0f, 10.0f, h));
  CHECK(h.t == doctest::Approx(3.0f));
  // Outside the interval.
  CHECK_FALSE(pr::rt::intersectTriangle(pr::rt::makeRayShear(ray), p0, p1, p2, 0.0f, 2.9f, h));
  CHECK_FALSE(pr::rt::intersectTriangle(pr::rt::makeRayShear(ray), p0, p1, p2, 3.1f, 10.0f, h));
}

TEST_CASE("Triangle: rays exactly through shared edges and vertices of a closed box never miss") {
  // From inside a closed, tessellated box every ray must hit; aim at the seams, where a
  // non-watertight test lets rays slip between neighbours. Off-centre origins at several
  // scales make the edge functions round differently.
  for (float scale : {1e-4f, 1.0f, 1e5f}) {
    CAPTURE(scale);
    const auto box = pr::test::closedBox(scale * glm::vec3(-1.0f, -0.7f, -1.3f), scale * glm::vec3(1.1f, 0.9f, 0.6f), 6);
    const Bvh bvh(box);
    const auto targets = edgePoints(box);
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> inside(-0.5f, 0.5f);
    int misses = 0;
    for (size_t i = 0; i < targets.size(); ++i) {
      const glm::vec3 origin = scale * glm::vec3(inside(rng), inside(rng), inside(rng));
      const Ray ray{origin, 0.0f, targets[i] - origin, pr::rt::kInfinity};
      Hit hit;
      if (!bvh.intersect(ray, hit)) ++misses;
      // The ray ends on the box: the hit is within rounding of t = 1.
      else CHECK(hit.t == doctest::Approx(1.0f).epsilon(1e-4));
    }
    CHECK(misses == 0);
  }
}

TEST_CASE("Triangle: rays through the vertices and edges of a height field never miss") {
  // Heights within +-0.1 on cells of 0.625 keep every surface slope below 0.33, and rays
  // start above the field at most 14.2 away horizontally while 24.9 above, so each ray meets
  // the surface once (no folds in its projection) and must hit at or before the target.
  const auto field = pr::test::heightField(16, 10.0f, 0.01f);
  const Bvh bvh(field);
  std::mt19937 rng(29);
  std::uniform_real_distribution<float> above(0.0f, 10.0f);
  int misses = 0, tested = 0;
  for (const glm::vec3& target : edgePoints(field)) {
    // Interior points only: rays through the outer border may pass just outside.
    if (target.x <= 0.0f || target.y <= 0.0f || target.x >= 10.0f || target.y >= 10.0f) continue;
    const glm::vec3 origin(above(rng), above(rng), 25.0f);
    Hit hit;
    if (!bvh.intersect(Ray{origin, 0.0f, target - origin, pr::rt::kInfinity}, hit)) ++misses;
    ++tested;
  }
  CHECK(tested > 5000);
  CHECK(misses == 0);
}

TEST_CASE("Triangle: grazing rays give finite results or none, never NaN") {
  // A ray in the triangle's plane has det = 0: no hit.
  pr::rt::TriangleHit h;
  const glm::vec3 p0(0, 0, 0), p1(1, 0, 0), p2(0, 1, 0);
  const Ray inPlane{{-1, 0.25f, 0}, 0.0f, {1, 0, 0}, pr::rt::kInfinity};
  CHECK_FALSE(pr::rt::intersectTriangle(pr::rt::makeRayShear(inPlane), p0, p1, p2, 0.0f, pr::rt::kInfinity, h));
  // Nearly parallel rays onto a large tessellated floor: the hit is where the geometry says.
  const auto floor = pr::test::heightField(8, 1000.0f, 0.0f);
  pr::scene::Scene flat = floor;
  for (auto& p : flat.positions) p.z = 0.0f;
  const Bvh bvh(flat);
  for (float slope : {1e-1f, 1e-2f, 1e-3f, 1e-4f}) {
    CAPTURE(slope);
    const Ray ray{{1.0f, 500.0f, 0.05f}, 0.0f, glm::normalize(glm::vec3(1.0f, 0.0f, -slope)), pr::rt::kInfinity};
    Hit hit;
    REQUIRE(bvh.intersect(ray, hit));
    CHECK(std::isfinite(hit.t));
    CHECK(std::isfinite(hit.u));
    CHECK(std::isfinite(hit.v));
    const float expected = 0.05f / (slope / std::sqrt(1.0f + slope * slope));
    CHECK(hit.t == doctest::Approx(expected).epsilon(1e-3));
  }
  // Grazing along a shared edge (the diagonal of a quad), slightly above and below the plane.
  for (float z : {1e-6f, -1e-6f}) {
    // Reaches the plane at (49, 49), on the diagonal of the first quad (side 125).
    const Ray alongEdge{{-1, -1, z}, 0.0f, glm::normalize(glm::vec3(1, 1, -z / 50.0f)), pr::rt::kInfinity};
    Hit hit;
    REQUIRE(bvh.intersect(alongEdge, hit));
    CHECK(std::isfinite(hit.t));
    CHECK(hit.t == doctest::Approx(50.0f * std::sqrt(2.0f)).epsilon(1e-3));
  }
}

TEST_CASE("Triangle: degenerate triangles are never hit and cause no NaN") {
  pr::scene::Scene scene = pr::test::emptyScene();
  pr::test::addTriangle(scene, {0, 0, 0}, {1, 1, 0}, {2, 2, 0});        // collinear
  pr::test::addTriangle(scene, {0, 0, 0}, {0.25f, 0.75f, 0}, {0.5f, 1.5f, 0});  // collinear, steep
  pr::test::addTriangle(scene, {3, 0, 0}, {3, 0, 0}, {3, 1, 0});        // repeated vertex
  pr::test::addTriangle(scene, {5, 5, 0}, {5, 5, 0}, {5, 5, 0});        // a point
  const float nan = std::nanf("");
  pr::test::addTriangle(scene, {nan, 0, 0}, {7, 0, 0}, {7, 1, 0});      // not finite
  const Bvh bvh(scene);
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> jitter(-3.0f, 3.0f);
  int hits = 0;
  // Rays aimed exactly at the triangles' vertices and edge points, from both sides.
  for (const auto& tri : scene.triangles)
    for (int k = 0; k <= 8; ++k) {
      const glm::vec3 a = scene.positions[tri.v[0]], b = scene.positions[tri.v[2]];
      glm::vec3 target = a + (b - a) * (float(k) / 8.0f);
      if (!std::isfinite(target.x)) target = scene.positions[tri.v[1]];
      for (float side : {4.0f, -4.0f}) {
        const glm::vec3 origin = target + glm::vec3(jitter(rng), jitter(rng), side);
        Hit hit;
        hits += bvh.intersect(Ray{origin, 0.0f, target - origin, pr::rt::kInfinity}, hit);
        hits += bvh.occluded(Ray{origin, 0.0f, target - origin, pr::rt::kInfinity});
        // Along the line of the collinear triangle.
        hits += bvh.intersect(Ray{{-1, -1, 0}, 0.0f, {1, 1, 0}, pr::rt::kInfinity}, hit);
      }
    }
  CHECK(hits == 0);
}

// The leaf test (triangle4.h) must be the scalar test, lane by lane, to the bit: images stay
// the same whichever test a leaf uses. The cases mix ordinary triangles with the hard ones:
// rays through a vertex or along an edge (edge functions exactly 0, the double fallback),
// degenerate triangles stored as three equal points, huge and tiny ones, and rays parallel to
// the plane.
TEST_CASE("Triangle: the four-lane leaf test gives the scalar test's hit, t, u and v bit for bit") {
  std::mt19937 rng(20261203);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const auto randomPoint = [&](float scale) { return glm::vec3(unit(rng), unit(rng), unit(rng)) * scale; };
  const auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
  int hits = 0, fallbacks = 0, compared = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const float scale = trial % 5 == 0 ? 1e4f : trial % 5 == 1 ? 1e-3f : 1.0f;
    const Ray ray{randomPoint(2.0f * scale), 0.0f, glm::normalize(randomPoint(1.0f) + glm::vec3(0.0f, 0.0f, 1e-3f)),
                  pr::rt::kInfinity};
    pr::rt::BvhTriangle tris[4];
    const uint32_t count = 1 + uint32_t(trial % 4);
    for (uint32_t i = 0; i < count; ++i) {
      glm::vec3 p0 = randomPoint(scale), p1 = randomPoint(scale), p2 = randomPoint(scale);
      switch ((trial / 4 + i) % 6) {
        case 0: p0 = ray.origin + ray.direction * (3.0f * scale); break;  // the ray through a vertex
        case 1: p1 = p0 + (p2 - p0) * 2.0f; break;                         // collinear: degenerate
        case 2: p1 = p2 = p0; break;                                       // as the build stores degenerates
        case 3: p1 = p0 + ray.direction * scale; break;                    // an edge along the ray
        default: break;
      }
      tris[i] = pr::rt::BvhTriangle{p0, p1, p2, i};
    }
    const pr::rt::BvhLeafBlock block = pr::rt::packLeafBlock(tris, count);
    const pr::rt::RayShear shear = pr::rt::makeRayShear(ray);
    const float tMax = trial % 3 == 0 ? 2.5f * scale : pr::rt::kInfinity;
    alignas(16) float t[4], u[4], v[4];
    int mask = 0;
    switch (shear.kz) {
      case 0: mask = pr::rt::intersectLeaf<0>(shear, block, count, 0.0f, tMax, t, u, v); break;
      case 1: mask = pr::rt::intersectLeaf<1>(shear, block, count, 0.0f, tMax, t, u, v); break;
      default: mask = pr::rt::intersectLeaf<2>(shear, block, count, 0.0f, tMax, t, u, v); break;
    }
    CHECK((mask >> count) == 0);
    for (uint32_t i = 0; i < count; ++i) {
      pr::rt::TriangleHit h;
      const bool scalarHit = pr::rt::intersectTriangle(shear, tris[i].p0, tris[i].p1, tris[i].p2, 0.0f, tMax, h);
      const bool leafHit = ((mask >> i) & 1) != 0;
      REQUIRE(leafHit == scalarHit);
      ++compared;
      if (!scalarHit) continue;
      ++hits;
      CHECK(bits(t[i]) == bits(h.t));
      CHECK(bits(u[i]) == bits(h.u));
      CHECK(bits(v[i]) == bits(h.v));
      fallbacks += (trial / 4 + i) % 6 == 0 ? 1 : 0;
    }
  }
  // The cases reach both outcomes and the through-a-vertex hits of the double fallback.
  CHECK(hits > 1000);
  CHECK(hits < compared);
  CHECK(fallbacks > 100);
}
