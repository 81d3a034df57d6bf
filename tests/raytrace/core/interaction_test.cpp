// Tests of surface interactions (raytrace/core/interaction.cpp): the data shading reads at a
// hit (position, normals, uv, material, facing) and the rays spawned from it.
#include <doctest/doctest.h>

#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/core/interaction.h"

using pr::rt::Hit;
using pr::rt::Ray;

namespace {

// One triangle in the plane z = 1 with normals, uvs and material 2.
pr::scene::Scene attributedTriangle(glm::vec3 n0, glm::vec3 n1, glm::vec3 n2) {
  pr::scene::Scene s = pr::test::emptyScene();
  s.materials.resize(3);
  pr::test::addTriangle(s, {0, 0, 1}, {2, 0, 1}, {0, 2, 1}, 2);
  s.normals = {glm::normalize(n0), glm::normalize(n1), glm::normalize(n2)};
  s.uvs = {{0, 0}, {1, 0}, {0, 1}};
  return s;
}

}  // namespace

TEST_CASE("Interaction: position, normals, uv and material at a hit") {
  const auto scene = attributedTriangle({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
  const pr::rt::Bvh bvh(scene);
  const Ray ray{{0.5f, 0.5f, 5.0f}, 0.0f, {0, 0, -2}, pr::rt::kInfinity};
  Hit hit;
  REQUIRE(bvh.intersect(ray, hit));
  const auto si = pr::rt::makeInteraction(scene, ray, hit);
  CHECK(si.t == doctest::Approx(2.0f));  // direction of length 2
  CHECK(si.position.x == doctest::Approx(0.5f));
  CHECK(si.position.y == doctest::Approx(0.5f));
  CHECK(si.position.z == 1.0f);
  CHECK(si.geometricNormal == glm::vec3(0, 0, 1));  // counter-clockwise seen from +z
  CHECK(si.frontFace);
  CHECK(si.wo == glm::vec3(0, 0, 1));
  CHECK(si.uv.x == doctest::Approx(0.25f));
  CHECK(si.uv.y == doctest::Approx(0.25f));
  CHECK(si.material == 2);
  CHECK(si.triangle == 0);
  CHECK(si.magnitude == glm::vec3(2.0f, 2.0f, 1.0f));
  // Shading normal: barycentric blend (0.5, 0.25, 0.25) of the unit vertex normals, normalised.
  const glm::vec3 blend = glm::normalize(0.5f * scene.normals[0] + 0.25f * scene.normals[1] + 0.25f * scene.normals[2]);
  CHECK(glm::length(si.shadingNormal - blend) < 1e-6f);
}

TEST_CASE("Interaction: facing and flipped vertex normals follow the winding") {
  // Vertex normals pointing to the back of the winding are flipped to its side.
  const auto scene = attributedTriangle({0, 0, -1}, {0, 0, -1}, {0, 0, -1});
  const pr::rt::Bvh bvh(scene);
  const Ray fromBelow{{0.5f, 0.5f, -1.0f}, 0.0f, {0, 0, 1}, pr::rt::kInfinity};
  Hit hit;
  REQUIRE(bvh.intersect(fromBelow, hit));
  const auto si = pr::rt::makeInteraction(scene, fromBelow, hit);
  CHECK_FALSE(si.frontFace);
  CHECK(si.geometricNormal == glm::vec3(0, 0, 1));
  CHECK(si.shadingNormal == glm::vec3(0, 0, 1));
  // Without vertex normals or uvs, shading uses the geometric normal and uv 0.
  pr::scene::Scene bare = scene;
  bare.normals.clear();
  bare.uvs.clear();
  const auto plain = pr::rt::makeInteraction(bare, fromBelow, hit);
  CHECK(plain.shadingNormal == plain.geometricNormal);
  CHECK(plain.uv == glm::vec2(0.0f));
}

TEST_CASE("Interaction: spawned rays start on the side they leave to") {
  const auto scene = attributedTriangle({0, 0, 1}, {0, 0, 1}, {0, 0, 1});
  const pr::rt::Bvh bvh(scene);
  const Ray ray{{0.5f, 0.5f, 5.0f}, 0.0f, {0, 0, -1}, pr::rt::kInfinity};
  Hit hit;
  REQUIRE(bvh.intersect(ray, hit));
  const auto si = pr::rt::makeInteraction(scene, ray, hit);
  // Reflected up: starts above the plane, does not see the triangle.
  const Ray up = pr::rt::spawnRay(si, glm::normalize(glm::vec3(1, 0, 1e-3f)));
  CHECK(up.origin.z > 1.0f);
  CHECK_FALSE(bvh.occluded(up));
  // Transmitted down: starts below.
  const Ray down = pr::rt::spawnRay(si, glm::normalize(glm::vec3(0.2f, 0.1f, -1.0f)));
  CHECK(down.origin.z < 1.0f);
  CHECK_FALSE(bvh.occluded(down));
  // To a point light: ends 1e-4 short of the light (so a light lying on a surface is not
  // shadowed by it), unoccluded.
  const glm::vec3 light(3.0f, -1.0f, 4.0f);
  const Ray shadow = pr::rt::spawnRayTo(si, light);
  CHECK(shadow.tMax == 1.0f - 1e-4f);
  CHECK(glm::length(shadow.origin + shadow.direction - light) < 1e-5f);
  CHECK_FALSE(bvh.occluded(shadow));
  // To a light below the plane the ray starts below: the cosine, not the surface, stops it.
  CHECK(pr::rt::spawnRayTo(si, glm::vec3(0.4f, 0.4f, -3.0f)).origin.z < 1.0f);
}
