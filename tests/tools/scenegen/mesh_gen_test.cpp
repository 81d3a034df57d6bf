// Tests of tools/scenegen/mesh_gen.cpp: triangle counts, outward counter-clockwise winding,
// unit normals that agree with the geometry, for quads, spheres, ellipsoids and height fields.
#include <doctest/doctest.h>

#include <cmath>

#include "tools/scenegen/mesh_gen.h"

using namespace pr::scenegen;

namespace {

glm::vec3 faceNormal(const MeshData& m, size_t t) {
  glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
            c = m.positions[m.indices[3 * t + 2]];
  return glm::cross(b - a, c - a);
}

glm::vec3 centroid(const MeshData& m, size_t t) {
  return (m.positions[m.indices[3 * t]] + m.positions[m.indices[3 * t + 1]] + m.positions[m.indices[3 * t + 2]]) / 3.0f;
}

}  // namespace

TEST_CASE("MeshGen: quad faces cross(u, v) with two triangles") {
  MeshData q = makeQuad({0, 0, 0}, {2, 0, 0}, {0, 0, -3});
  REQUIRE(q.triangleCount() == 2);
  for (size_t t = 0; t < 2; ++t) {
    glm::vec3 n = faceNormal(q, t);
    CHECK(n.y > 0.0f);
    CHECK(glm::length(n) == doctest::Approx(6.0f));  // each triangle is half the 2 x 3 area, x2
  }
  CHECK(q.normals[0] == glm::vec3(0, 1, 0));
}

TEST_CASE("MeshGen: UV sphere has 2 s (r-1) outward, non-degenerate triangles and radial normals") {
  const int segments = 16, rings = 8;
  MeshData s = makeUvSphere(2.0f, segments, rings);
  REQUIRE(s.triangleCount() == size_t(2 * segments * (rings - 1)));
  REQUIRE(s.normals.size() == s.positions.size());
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    glm::vec3 n = faceNormal(s, t);
    CHECK(glm::length(n) > 1e-4f);                    // no pole slivers
    CHECK(glm::dot(n, centroid(s, t)) > 0.0f);        // counter-clockwise seen from outside
  }
  for (size_t i = 0; i < s.positions.size(); ++i) {
    CHECK(glm::length(s.positions[i]) == doctest::Approx(2.0f));
    CHECK(glm::length(s.normals[i] - s.positions[i] / 2.0f) < 1e-5f);
  }
}

TEST_CASE("MeshGen: a box has 12 outward triangles on its six faces, standing on the origin") {
  const glm::vec3 size(2.0f, 3.0f, 4.0f);
  MeshData b = makeBox(size);
  REQUIRE(b.triangleCount() == 12);
  const glm::vec3 centre(0.0f, 1.5f, 0.0f);
  for (size_t t = 0; t < 12; ++t) {
    const glm::vec3 n = faceNormal(b, t), c = centroid(b, t);
    CHECK(glm::dot(n, c - centre) > 0.0f);  // counter-clockwise seen from outside
    // The vertex normal is the face's, and the face lies on the box's side it points to.
    const glm::vec3 vn = b.normals[b.indices[3 * t]];
    CHECK(glm::length(glm::normalize(n) - vn) < 1e-6f);
    CHECK(glm::dot(c - centre, vn) == doctest::Approx(0.5f * glm::dot(glm::abs(vn), size)));
  }
  for (const glm::vec3& p : b.positions) {
    CHECK(std::fabs(p.x) == doctest::Approx(1.0f));
    CHECK((p.y == 0.0f || p.y == 3.0f));
    CHECK(std::fabs(p.z) == doctest::Approx(2.0f));
  }
}

TEST_CASE("MeshGen: ellipsoid normals are the surface gradient, not the scaled sphere's") {
  const glm::vec3 c(1, 2, 3), r(1.5f, 0.5f, 1.5f);
  MeshData e = makeEllipsoid(c, r, 24, 12);
  for (size_t i = 0; i < e.positions.size(); ++i) {
    glm::vec3 q = (e.positions[i] - c) / r;
    CHECK(glm::dot(q, q) == doctest::Approx(1.0f));  // on the surface
    glm::vec3 gradient = glm::normalize((e.positions[i] - c) / (r * r));
    CHECK(glm::length(e.normals[i] - gradient) < 1e-4f);
  }
  for (size_t t = 0; t < e.triangleCount(); ++t) CHECK(glm::dot(faceNormal(e, t), centroid(e, t) - c) > 0.0f);
}

TEST_CASE("MeshGen: height field has 2 n^2 upward triangles on the sampled heights") {
  auto height = [](float x, float z) { return 0.5f * x - 0.25f * z; };  // a plane: exact normals
  MeshData h = makeHeightField(4, -2.0f, -2.0f, 4.0f, height);
  REQUIRE(h.positions.size() == 25);
  REQUIRE(h.triangleCount() == 32);
  for (size_t i = 0; i < h.positions.size(); ++i) {
    CHECK(h.positions[i].y == doctest::Approx(height(h.positions[i].x, h.positions[i].z)));
    // Plane y = 0.5x - 0.25z has normal (-0.5, 1, 0.25) / |.|, at the border too.
    CHECK(glm::length(h.normals[i] - glm::normalize(glm::vec3(-0.5f, 1.0f, 0.25f))) < 1e-5f);
  }
  for (size_t t = 0; t < h.triangleCount(); ++t) CHECK(faceNormal(h, t).y > 0.0f);
  CHECK(h.positions.front() == glm::vec3(-2.0f, height(-2, -2), -2.0f));
  CHECK(h.positions.back().x == doctest::Approx(2.0f));
}
