// Tests of precomputed irradiance (photonmap/precomputed_irradiance.h): on a uniformly lit
// ground plane a precomputed point's irradiance is the density estimate there, a query reads the nearest point of the same surface, and a query from
// the other side of the surface or beyond the radius gets nothing.
#include <doctest/doctest.h>

#include <vector>

#include "common/parallel/runtime.h"
#include "photonmap/photon_test_support.h"
#include "photonmap/precomputed_irradiance.h"

using namespace pr;

TEST_CASE("PrecomputedIrradiance: points on a lit plane carry the density estimate and the plane's normal") {
  // 20000 photons on the ground (y = 0) from above, irradiance E = 3 everywhere.
  test::TestRng rng(5);
  const float e = 3.0f;
  const int n = 20000;
  std::vector<pm::Photon> photons;
  for (int i = 0; i < n; ++i)
    photons.push_back(pm::Photon::make({rng.uniform(-1.0f, 1.0f), 0.0f, rng.uniform(-1.0f, 1.0f)}, glm::vec3(e * 4.0f / n),
                                       glm::normalize(glm::vec3(rng.uniform(-0.5f, 0.5f), 1.0f, rng.uniform(-0.5f, 0.5f)))));
  const pm::KdTree global = pm::KdTree::build(photons);
  const std::vector<glm::vec3> normals(photons.size(), glm::vec3(0.0f, 1.0f, 0.0f));
  pm::DensityOptions density;
  density.k = 100;
  density.maxRadius = 0.3f;
  par::Runtime runtime(2);
  const pm::PrecomputedIrradiance points = pm::PrecomputedIrradiance::build(photons, normals, global, density, 4, runtime);
  CHECK(points.size() == n / 4);  // every 4th photon
  pm::NearestPhotons scratch;
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  for (const glm::vec3 x : {glm::vec3(0.0f), glm::vec3(0.3f, 0.0f, -0.2f), glm::vec3(-0.5f, 0.0f, 0.4f)}) {
    const glm::vec3 read = points.irradiance(x, up, density.maxRadius, scratch);
    const pm::DensityEstimate direct = pm::estimateIrradiance(global, x, up, density);
    CAPTURE(x.x);
    CHECK(read.x == doctest::Approx(e).epsilon(0.35));  // 3/sqrt(k) + RGBE
    CHECK(read.x == doctest::Approx(direct.irradiance.x).epsilon(0.35));
    // From below the plane, or beyond the radius, there is no point of this surface.
    CHECK(points.irradiance(x, -up, density.maxRadius, scratch) == glm::vec3(0.0f));
    CHECK(points.irradiance(x + glm::vec3(0.0f, 5.0f, 0.0f), up, density.maxRadius, scratch) == glm::vec3(0.0f));
  }
  // The same points for every P.
  par::Runtime serial(1);
  const pm::PrecomputedIrradiance again = pm::PrecomputedIrradiance::build(photons, normals, global, density, 4, serial);
  CHECK(again.size() == points.size());
  CHECK(again.irradiance(glm::vec3(0.1f, 0.0f, 0.1f), up, density.maxRadius, scratch) ==
        points.irradiance(glm::vec3(0.1f, 0.0f, 0.1f), up, density.maxRadius, scratch));
}
