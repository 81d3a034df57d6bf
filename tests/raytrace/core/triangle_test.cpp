// Tests of the watertight ray-triangle test (raytrace/core/triangle.h), alone and through the
// BVH: rays exactly through shared edges and vertices never miss, grazing rays give no NaN,
// degenerate triangles are never hit.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/core/triangle.h"

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
