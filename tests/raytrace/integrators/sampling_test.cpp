// Sampling: counter-based random numbers are pure functions of their counters and uniform;
// stratified pixel samples fill their strata; warps stay on their domains.
#include <cmath>
#include <set>
#include <vector>

#include <doctest/doctest.h>

#include "raytrace/integrators/sampling.h"

using namespace pr::rt;

TEST_CASE("Sampling: a number depends only on (seed, pixel, sample, depth, dimension)") {
  const float a = sample1D(7, 123, 4, 2, Dim::kBsdfU);
  CHECK(a == sample1D(7, 123, 4, 2, Dim::kBsdfU));
  CHECK(a != sample1D(8, 123, 4, 2, Dim::kBsdfU));
  CHECK(a != sample1D(7, 124, 4, 2, Dim::kBsdfU));
  CHECK(a != sample1D(7, 123, 5, 2, Dim::kBsdfU));
  CHECK(a != sample1D(7, 123, 4, 3, Dim::kBsdfU));
  CHECK(a != sample1D(7, 123, 4, 2, Dim::kBsdfV));
}

TEST_CASE("Sampling: numbers lie in the half-open unit interval with mean 1/2 and variance 1/12") {
  double sum = 0.0, sum2 = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const float u = sample1D(1, uint32_t(i), 0, 0, 0);
    REQUIRE(u >= 0.0f);
    REQUIRE(u < 1.0f);
    sum += u;
    sum2 += double(u) * u;
  }
  const double mean = sum / n;
  // Standard error of the mean is sqrt(1/12 / n) = 0.0009; 5 sigma.
  CHECK(std::fabs(mean - 0.5) < 0.0046);
  CHECK(std::fabs(sum2 / n - mean * mean - 1.0 / 12.0) < 0.002);
}

TEST_CASE("Sampling: stratified pixel samples put one sample in each stratum for any spp") {
  for (int spp : {1, 2, 3, 4, 6, 7, 9, 16}) {
    const glm::ivec2 n = strataFor(spp);
    CHECK(n.x * n.y == spp);
    std::set<int> cells;
    for (int s = 0; s < spp; ++s) {
      const glm::vec2 p = stratifiedPixelSample(s, spp, sample1D(1, 0, uint32_t(s), 0, 0), sample1D(1, 0, uint32_t(s), 0, 1));
      REQUIRE(p.x < 1.0f);
      REQUIRE(p.y < 1.0f);
      cells.insert(int(p.x * float(n.x)) + n.x * int(p.y * float(n.y)));
    }
    CHECK(cells.size() == size_t(spp));
  }
}

TEST_CASE("Sampling: cosine hemisphere has unit directions above the plane with mean cos 2/3") {
  double meanCos = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 d = cosineHemisphere(sample1D(2, uint32_t(i), 0, 0, 0), sample1D(2, uint32_t(i), 0, 0, 1));
    REQUIRE(std::fabs(glm::length(d) - 1.0f) < 1e-5f);
    REQUIRE(d.z >= 0.0f);
    meanCos += d.z;
  }
  // E[cos] under pdf cos/pi is 2/3; its standard deviation is sqrt(1/2 - 4/9) = 0.236.
  CHECK(std::fabs(meanCos / n - 2.0 / 3.0) < 5 * 0.236 / std::sqrt(double(n)));
}

TEST_CASE("Sampling: frames are orthonormal for any normal, including -z") {
  for (glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::normalize(glm::vec3(1, 2, 3)), glm::vec3(1, 0, 0)}) {
    const Frame f(n);
    CHECK(std::fabs(glm::dot(f.s, f.t)) < 1e-6f);
    CHECK(std::fabs(glm::dot(f.s, f.n)) < 1e-6f);
    CHECK(std::fabs(glm::length(f.s) - 1.0f) < 1e-6f);
    const glm::vec3 v(0.3f, -0.5f, 0.8f);
    const glm::vec3 back = f.toLocal(f.toWorld(v));
    CHECK(glm::length(back - v) < 1e-5f);
  }
}

TEST_CASE("Sampling: uniform triangle barycentrics stay inside the triangle") {
  for (int i = 0; i < 1000; ++i) {
    const glm::vec2 b = uniformTriangle(sample1D(3, uint32_t(i), 0, 0, 0), sample1D(3, uint32_t(i), 0, 0, 1));
    CHECK(b.x >= 0.0f);
    CHECK(b.y >= 0.0f);
    CHECK(b.x + b.y <= 1.0f);
  }
}
