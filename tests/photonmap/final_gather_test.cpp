// Tests of final gathering (photonmap/final_gather.h) inside a closed box whose walls carry a
// synthetic global map: uniform walls give E = rho E_photons (a closed Lambertian enclosure of
// radiance L gives E = pi L), near-zero gradients and a harmonic mean distance between the
// nearest and farthest walls; with one wall brighter, the translation gradient predicts the
// change of the gathered irradiance between two nearby points.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "photonmap/final_gather.h"
#include "raytrace/core/bvh.h"
#include "raytrace/integrators/integrator_scenes.h"

using namespace pr;

namespace {

constexpr float kAlbedo = 0.5f;
constexpr int kPhotonsPerFace = 40000;
constexpr float kPower = 1.0e-4f;

// The cube [-1, 1]^3 seen from inside (every face facing in), diffuse walls.
scene::Scene insideCube() {
  scene::Scene s;
  const uint32_t mat = test::addMaterial(s, test::diffuse(kAlbedo));
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      auto corner = [&](float a, float b) {
        glm::vec3 p(0.0f);
        p[axis] = side;
        p[u] = a;
        p[v] = b;
        return p;
      };
      // Wound so that the face's normal points to -side along axis (into the cube).
      const glm::vec3 p00 = corner(-1, -1), p10 = corner(1, -1), p11 = corner(1, 1), p01 = corner(-1, 1);
      if (side > 0) {
        test::addTri(s, p00, p10, p11, mat);
        test::addTri(s, p00, p11, p01, mat);
      } else {
        test::addTri(s, p00, p11, p10, mat);
        test::addTri(s, p00, p01, p11, mat);
      }
    }
  return s;
}

// Photons spread uniformly over each face, arriving from inside; face +x carries `brightX`
// times the power of the others. Irradiance of a face: kPower * kPhotonsPerFace / 4 (x bright).
pm::KdTree wallPhotons(float brightX) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<pm::Photon> photons;
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      glm::vec3 inward(0.0f);
      inward[axis] = -side;
      const float power = kPower * (axis == 0 && side > 0 ? brightX : 1.0f);
      for (int i = 0; i < kPhotonsPerFace; ++i) {
        glm::vec3 p(u(rng), u(rng), u(rng));
        p[axis] = side;
        photons.push_back(pm::Photon::make(p, glm::vec3(power), glm::normalize(inward + 0.5f * glm::vec3(u(rng), u(rng), u(rng)) * (glm::vec3(1.0f) - glm::abs(inward))), pm::PhotonMapKind::Global, 1));
      }
    }
  return pm::KdTree::build(std::move(photons));
}

// A surface point on the floor (y = -1) at (x, z), facing up.
rt::SurfaceInteraction floorPoint(const scene::Scene& s, const rt::Bvh& bvh, float x, float z) {
  const rt::Ray down{glm::vec3(x, 0.0f, z), 0.0f, glm::vec3(0.0f, -1.0f, 0.0f), rt::kInfinity};
  rt::Hit hit;
  REQUIRE(bvh.intersect(down, hit));
  return rt::makeInteraction(s, down, hit);
}

pm::GatherOptions options() {
  pm::GatherOptions o;
  o.rays = 1024;
  o.global.k = 50;
  o.global.maxRadius = 0.2f;
  return o;
}

}  // namespace

TEST_CASE("FinalGather: inside a uniformly lit closed box the record's irradiance is rho E_photons") {
  const scene::Scene s = insideCube();
  const rt::Bvh bvh(s);
  const pm::KdTree map = wallPhotons(1.0f);
  pm::NearestPhotons scratch;
  std::uint64_t rays = 0;
  const pm::IrradianceRecord r = pm::gatherIrradiance(s, bvh, map, floorPoint(s, bvh, 0.0f, 0.0f), 7, options(), scratch, rays);
  const float photonIrradiance = kPower * float(kPhotonsPerFace) / 4.0f;
  CHECK(rays >= 1000);
  for (int c = 0; c < 3; ++c) CHECK(r.irradiance[c] == doctest::Approx(kAlbedo * photonIrradiance).epsilon(0.04));
  // Uniform light: the gradients are noise around zero (well below E / R).
  const float e = r.irradiance.x;
  CHECK(glm::length(r.translationGradient[0]) * r.radius < 0.15f * e);
  CHECK(glm::length(r.rotationGradient[0]) < 0.15f * e);
  // Harmonic mean of wall distances between the ceiling's 2 and the nearest wall's 1.
  CHECK(r.radius > 1.0f);
  CHECK(r.radius < 2.0f);
  CHECK(r.normal == glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST_CASE("FinalGather: the translation gradient predicts the irradiance change towards a brighter wall") {
  const scene::Scene s = insideCube();
  const rt::Bvh bvh(s);
  const pm::KdTree map = wallPhotons(5.0f);
  pm::NearestPhotons scratch;
  std::uint64_t rays = 0;
  const float d = 0.15f;
  const pm::IrradianceRecord centre = pm::gatherIrradiance(s, bvh, map, floorPoint(s, bvh, 0.0f, 0.0f), 1, options(), scratch, rays);
  const pm::IrradianceRecord left = pm::gatherIrradiance(s, bvh, map, floorPoint(s, bvh, -d, 0.0f), 1, options(), scratch, rays);
  const pm::IrradianceRecord right = pm::gatherIrradiance(s, bvh, map, floorPoint(s, bvh, d, 0.0f), 1, options(), scratch, rays);
  const float measured = (right.irradiance.x - left.irradiance.x) / (2.0f * d);
  const glm::vec3 g = centre.translationGradient[0];
  CAPTURE(measured);
  CAPTURE(g.x);
  REQUIRE(measured > 0.0f);  // nearer the bright wall, brighter
  CHECK(g.x == doctest::Approx(measured).epsilon(0.25));
  CHECK(std::fabs(g.z) < 0.2f * g.x);  // symmetric in z
  // The rotation gradient points the same way: tilting the normal towards +x sees more of it.
  // (n_i x n) . grad_r > 0 for n tilted to +x, n_i x n = (0, 0, -s): grad_r.z < 0.
  CHECK(centre.rotationGradient[0].z < 0.0f);
}
