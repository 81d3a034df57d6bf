// Tests of the photon-map density estimate (photonmap/density_estimate.h): a uniformly lit
// plane against its analytic irradiance with a tolerance that shrinks as photons are added,
// thin-wall and back-face rejection, the minimum photon count, and the numerical hazards
// (radius zero, no photons, one photon, coincident photons).
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "photonmap/density_estimate.h"
#include "photonmap/photon_test_support.h"

using pr::pm::DensityFilter;
using pr::pm::DensityOptions;
using pr::pm::KdTree;
using pr::pm::Photon;
using pr::pm::estimateIrradiance;

namespace {

constexpr float kPi = 3.14159265358979323846f;

// n photons spread uniformly at random over the square [-h, h]^2 of the plane z = 0, arriving
// from above (wi = +z), carrying E * area / n each: the analytic irradiance everywhere is E.
std::vector<Photon> litPlane(std::size_t n, float h, float irradiance, std::uint64_t seed) {
  pr::test::TestRng rng(seed);
  const float power = irradiance * (2 * h) * (2 * h) / static_cast<float>(n);
  std::vector<Photon> photons(n);
  for (auto& p : photons)
    p = Photon::make({rng.uniform(-h, h), rng.uniform(-h, h), 0.0f}, glm::vec3(power), {0, 0, 1});
  return photons;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

TEST_CASE("DensityEstimate: a uniformly lit plane gives the analytic irradiance, closer with more photons") {
  // The k nearest of a uniform (binomial ~ Poisson) photon set: k / (pi r_k^2) has relative
  // standard deviation about 1/sqrt(k) and a bias of about 1/(k-1) (Jensen's estimator counts
  // the k-th photon, which sits on the disc's edge). Tolerance 3/sqrt(k) + 1/(k-1), at points
  // well inside the plane (the disc never reaches an edge); k grows with the photon count, so
  // the tolerance shrinks as 1/sqrt(n): 1.1 at 10^3 photons, 0.33 at 10^4, 0.10 at 10^5. The
  // power is packed as RGBE (error <= 0.4 %), far inside these bounds.
  const float h = 1.0f, e = 5.0f;
  const glm::vec3 n(0, 0, 1);
  for (std::size_t count : {1000u, 10000u, 100000u}) {
    const KdTree map = KdTree::build(litPlane(count, h, e, count));
    DensityOptions options;
    options.k = static_cast<int>(count / 100);
    options.maxRadius = 0.5f;  // large enough that k photons are always found
    const float tolerance = 3.0f / std::sqrt(static_cast<float>(options.k)) + 1.0f / (options.k - 1);
    float worst = 0.0f;
    for (const glm::vec3 x : {glm::vec3(0, 0, 0), glm::vec3(0.3f, 0.1f, 0), glm::vec3(-0.2f, 0.4f, 0),
                              glm::vec3(0.45f, -0.35f, 0)}) {
      for (DensityFilter filter : {DensityFilter::Box, DensityFilter::Cone}) {
        options.filter = filter;
        const auto est = estimateIrradiance(map, x, n, options);
        CHECK(est.photons == options.k);
        CHECK(est.rejected == 0);
        const float error = std::abs(est.irradiance.x - e) / e;
        CHECK(error < tolerance);
        worst = std::max(worst, error);
      }
    }
    MESSAGE(count << " photons, k = " << options.k << ": worst relative error " << worst << " (bound " << tolerance << ")");
  }
}

TEST_CASE("DensityEstimate: photons behind a thin wall and back-face photons are not counted") {
  // The query point sits on the front face (z = 0, normal +z) of a wall 0.02 thick; maxRadius
  // 0.1, so the disc thickness is 0.01. The front is lit by photons from above; the back face
  // (z = -0.02) by photons from below; and some photons on the front plane arrive from below
  // (wi = -z: they crossed the surface, e.g. a coplanar face of another object).
  const float h = 1.0f;
  const std::vector<Photon> front = litPlane(20000, h, 2.0f, 1);
  std::vector<Photon> behind, backFacing;
  pr::test::TestRng rng(2);
  for (int i = 0; i < 20000; ++i) {
    const glm::vec3 p(rng.uniform(-h, h), rng.uniform(-h, h), 0.0f);
    behind.push_back(Photon::make(p + glm::vec3(0, 0, -0.02f), glm::vec3(1.0f), {0, 0, -1}));
    // Facing the query's side would be wrong for these too: even a photon behind the wall
    // arriving from above is rejected by its offset alone.
    behind.push_back(Photon::make(p + glm::vec3(0, 0, -0.02f), glm::vec3(1.0f), {0, 0, 1}));
    backFacing.push_back(Photon::make(p, glm::vec3(1.0f), {0, 0, -1}));
  }
  DensityOptions options;
  options.k = 50;
  options.maxRadius = 0.1f;
  const glm::vec3 x(0.1f, -0.2f, 0.0f), n(0, 0, 1);

  // Only the dark side's photons: exactly no light.
  for (const auto* set : {&behind, &backFacing}) {
    const auto est = estimateIrradiance(KdTree::build(*set), x, n, options);
    CHECK(est.irradiance == glm::vec3(0.0f));
    CHECK(est.photons == 0);
    CHECK(est.rejected > 0);
  }
  // Front photons with the others mixed in: the same estimate as the front photons alone (the
  // same k photons; the sums may differ in the last bit by their order).
  std::vector<Photon> all = front;
  all.insert(all.end(), behind.begin(), behind.end());
  all.insert(all.end(), backFacing.begin(), backFacing.end());
  const auto alone = estimateIrradiance(KdTree::build(front), x, n, options);
  const auto mixed = estimateIrradiance(KdTree::build(all), x, n, options);
  CHECK(mixed.photons == 50);
  CHECK(mixed.rejected > 0);
  CHECK(mixed.radiusSq == alone.radiusSq);
  CHECK(mixed.irradiance.x == doctest::Approx(alone.irradiance.x).epsilon(1e-5));
  // Seen from the back face (normal -z at z = -0.02) only the photons arriving from below count.
  const auto back = estimateIrradiance(KdTree::build(all), x + glm::vec3(0, 0, -0.02f), -n, options);
  CHECK(back.photons == 50);
}

TEST_CASE("DensityEstimate: a sparse region keeps its photons over the maximum disc, unbiased") {
  // 3 photons in the disc, fewer than k: their power over the whole maximum disc (the default
  // keeps any count; a minimum of 8 would make the region black).
  std::vector<Photon> photons;
  for (int i = 0; i < 3; ++i) photons.push_back(Photon::make({0.01f * i, 0, 0}, glm::vec3(1.0f), {0, 0, 1}));
  DensityOptions options;
  options.k = 50;
  options.maxRadius = 0.1f;
  const auto three = estimateIrradiance(KdTree::build(photons), {0, 0, 0}, {0, 0, 1}, options);
  CHECK(three.photons == 3);
  CHECK(three.irradiance.x == doctest::Approx(3.0f / (kPi * 0.01f)).epsilon(1e-5));
  options.minPhotons = 8;
  CHECK(estimateIrradiance(KdTree::build(photons), {0, 0, 0}, {0, 0, 1}, options).irradiance == glm::vec3(0.0f));

  // A faint field, 2 photons per maximum disc on average: the estimate's mean over many points
  // is the field's irradiance (within 5 %), where a minimum of 8 photons would give almost none.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float power = 0.5f;
  const int count = 2000;  // on the unit square: E = count * power
  std::vector<Photon> field;
  for (int i = 0; i < count; ++i) field.push_back(Photon::make({u(rng), u(rng), 0}, glm::vec3(power), {0, 0, 1}));
  const KdTree map = KdTree::build(field);
  options.maxRadius = std::sqrt(2.0f / (kPi * float(count)));
  double sum = 0.0, trimmed = 0.0;
  const int points = 4000;
  for (int i = 0; i < points; ++i) {
    const glm::vec3 x(0.1f + 0.8f * u(rng), 0.1f + 0.8f * u(rng), 0.0f);
    options.minPhotons = 1;
    sum += estimateIrradiance(map, x, {0, 0, 1}, options).irradiance.x;
    options.minPhotons = 8;
    trimmed += estimateIrradiance(map, x, {0, 0, 1}, options).irradiance.x;
  }
  const double expected = double(count) * power;
  CHECK(sum / points == doctest::Approx(expected).epsilon(0.05));
  CHECK(trimmed / points < 0.05 * expected);
}

TEST_CASE("DensityEstimate: radius zero, no photons, one photon and coincident photons are finite") {
  const glm::vec3 x(0, 0, 0), n(0, 0, 1);
  DensityOptions options;
  options.k = 10;
  options.maxRadius = 0.0f;
  const KdTree one = KdTree::build({Photon::make(x, glm::vec3(1.0f), n)});
  auto zero = [](const pr::pm::DensityEstimate& est) {
    return finite(est.irradiance) && est.irradiance == glm::vec3(0.0f) && est.photons == 0;
  };
  CHECK(zero(estimateIrradiance(one, x, n, options)));  // radius zero
  options.maxRadius = std::numeric_limits<float>::quiet_NaN();
  CHECK(zero(estimateIrradiance(one, x, n, options)));
  options.maxRadius = 0.1f;
  CHECK(zero(estimateIrradiance(KdTree::build({}), x, n, options)));  // no photons
  options.minPhotons = 2;
  CHECK(zero(estimateIrradiance(one, x, n, options)));                  // one photon, below the minimum
  options.minPhotons = 1;
  const auto single = estimateIrradiance(one, x, n, options);           // one photon, allowed
  CHECK(finite(single.irradiance));
  CHECK(single.irradiance.x == doctest::Approx(1.0f / (kPi * 0.01f)).epsilon(1e-5));
  options.minPhotons = 0;
  options.k = 1;
  // k photons all exactly at x: a zero-area disc, no density.
  CHECK(zero(estimateIrradiance(one, x, n, options)));
  const KdTree stack = KdTree::build(std::vector<Photon>(20, Photon::make(x, glm::vec3(1.0f), n)));
  options.k = 10;
  CHECK(zero(estimateIrradiance(stack, x, n, options)));
  options.filter = DensityFilter::Cone;
  CHECK(zero(estimateIrradiance(stack, x, n, options)));
  // A tiny disc whose density would overflow a float: zero, not Inf.
  const KdTree tight = KdTree::build({Photon::make(x, glm::vec3(1e30f), n), Photon::make({1e-20f, 0, 0}, glm::vec3(1e30f), n)});
  options.k = 2;
  options.filter = DensityFilter::Box;
  CHECK(finite(estimateIrradiance(tight, x, n, options).irradiance));
  options.k = 0;
  CHECK(zero(estimateIrradiance(stack, x, n, options)));
}

TEST_CASE("DensityEstimate: Lambertian radiance is albedo / pi times irradiance") {
  const glm::vec3 l = pr::pm::lambertianRadiance({0.5f, 0.25f, 1.0f}, glm::vec3(kPi));
  CHECK(l.x == doctest::Approx(0.5f));
  CHECK(l.y == doctest::Approx(0.25f));
  CHECK(l.z == doctest::Approx(1.0f));
}
