// Tests of the irradiance cache (photonmap/irradiance_cache.h): a record reproduces its own
// irradiance and is unused beyond its reach; its gradients extrapolate linearly; neighbour
// clamping shrinks a large record next to a small one; the octree finds exactly the records a
// brute-force scan does, and gives the brute-force weighted mean bit for bit; no NaN at a record.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "photonmap/irradiance_cache.h"

using namespace pr;

namespace {

scene::Bounds box(float h) { return scene::Bounds{glm::vec3(-h), glm::vec3(h)}; }

pm::IrradianceRecord record(glm::vec3 p, glm::vec3 n, glm::vec3 e, float radius) {
  pm::IrradianceRecord r;
  r.position = p;
  r.normal = n;
  r.irradiance = e;
  r.radius = radius;
  return r;
}

// The cache's rule written out plainly over every record in index order.
bool bruteForce(const std::vector<pm::IrradianceRecord>& records, float a, glm::vec3 x, glm::vec3 n, glm::vec3& e) {
  float weights = 0.0f;
  glm::vec3 sum(0.0f);
  for (const pm::IrradianceRecord& r : records) {
    const glm::vec3 d = x - r.position;
    if (glm::dot(d, 0.5f * (n + r.normal)) < -0.05f * r.radius) continue;
    const float eps = glm::length(d) / r.radius + std::sqrt(std::max(0.0f, 1.0f - glm::dot(n, r.normal)));
    if (!(eps < a)) continue;
    const float w = std::min(1.0e6f, 1.0f / std::max(eps, 1.0e-6f) - 1.0f / a);
    if (!(w > 0.0f)) continue;
    glm::vec3 v;
    for (int c = 0; c < 3; ++c)
      v[c] = std::max(0.0f, r.irradiance[c] + glm::dot(glm::cross(r.normal, n), r.rotationGradient[c]) +
                                glm::dot(d, r.translationGradient[c]));
    sum += w * v;
    weights += w;
  }
  if (!(weights > 0.0f)) return false;
  e = sum / weights;
  return true;
}

}  // namespace

TEST_CASE("IrradianceCache: a record gives its irradiance at its position and nothing beyond its reach") {
  pm::IrradianceCache cache(box(10.0f), 0.25f);
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  cache.insert(record(glm::vec3(0.0f), up, glm::vec3(1.0f, 2.0f, 3.0f), 2.0f));
  glm::vec3 e(-1.0f);
  REQUIRE(cache.lookup(glm::vec3(0.0f), up, e));  // eps = 0: the weight is capped, not infinite
  CHECK(e == glm::vec3(1.0f, 2.0f, 3.0f));
  CHECK(cache.lookup(glm::vec3(0.4f, 0.0f, 0.0f), up, e));   // 0.4 / 2 = 0.2 < a
  CHECK_FALSE(cache.lookup(glm::vec3(0.5f, 0.0f, 0.0f), up, e));  // 0.5 / 2 = a
  CHECK_FALSE(cache.lookup(glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), e));  // normal 90 degrees off
  CHECK_FALSE(cache.covers(glm::vec3(5.0f, 0.0f, 0.0f), up));
  CHECK(cache.covers(glm::vec3(0.1f, 0.0f, 0.0f), up));
}

TEST_CASE("IrradianceCache: translation and rotation gradients extrapolate the record") {
  pm::IrradianceCache cache(box(10.0f), 0.5f);
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  pm::IrradianceRecord r = record(glm::vec3(0.0f), up, glm::vec3(1.0f), 4.0f);
  r.translationGradient[0] = glm::vec3(0.5f, 0.0f, 0.0f);
  r.rotationGradient[1] = glm::vec3(0.0f, 0.0f, 2.0f);
  cache.insert(r);
  glm::vec3 e;
  REQUIRE(cache.lookup(glm::vec3(0.6f, 0.0f, 0.0f), up, e));
  CHECK(e.x == doctest::Approx(1.0f + 0.5f * 0.6f));
  CHECK(e.y == doctest::Approx(1.0f));
  // n tilted towards +x: n_i x n = (0, 1, 0) x (s, c, 0) = (0, 0, -s).
  const float s = 0.1f;
  const glm::vec3 tilted = glm::normalize(glm::vec3(s, 1.0f, 0.0f));
  REQUIRE(cache.lookup(glm::vec3(0.0f), tilted, e));
  CHECK(e.y == doctest::Approx(1.0f - 2.0f * tilted.x).epsilon(1e-5));
  CHECK(e.x == doctest::Approx(1.0f));
}

TEST_CASE("IrradianceCache: neighbour clamping shrinks a large record next to a small one, both ways") {
  pm::IrradianceCache cache(box(10.0f), 0.25f);
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  cache.insert(record(glm::vec3(0.0f), up, glm::vec3(1.0f), 10.0f));
  cache.insert(record(glm::vec3(1.0f, 0.0f, 0.0f), up, glm::vec3(1.0f), 0.1f));
  REQUIRE(cache.size() == 2);
  CHECK(cache.records()[0].radius == doctest::Approx(1.1f));  // R_0 <= R_1 + |x_0 - x_1|
  CHECK(cache.records()[1].radius == doctest::Approx(0.1f));
  // A record inserted far away, beyond the reach of both, changes neither.
  cache.insert(record(glm::vec3(8.0f, 0.0f, 0.0f), up, glm::vec3(1.0f), 1.0f));
  CHECK(cache.records()[0].radius == doctest::Approx(1.1f));
  CHECK(cache.records()[2].radius == doctest::Approx(1.0f));
}

TEST_CASE("IrradianceCache: the octree gives the brute-force interpolation bit for bit") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_real_distribution<float> radius(0.3f, 4.0f);
  const float a = 0.3f;
  pm::IrradianceCache cache(box(5.0f), a);
  for (int i = 0; i < 400; ++i) {
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f * u(rng), 1.0f, 0.3f * u(rng)));
    pm::IrradianceRecord r = record(glm::vec3(4.0f * u(rng), 0.2f * u(rng), 4.0f * u(rng)), n,
                                    glm::vec3(1.0f + u(rng), 1.5f + u(rng), 2.0f + u(rng)), radius(rng));
    for (int c = 0; c < 3; ++c) {
      r.translationGradient[c] = 0.1f * glm::vec3(u(rng), u(rng), u(rng));
      r.rotationGradient[c] = 0.1f * glm::vec3(u(rng), u(rng), u(rng));
    }
    cache.insert(r);
  }
  int used = 0;
  for (int q = 0; q < 2000; ++q) {
    const glm::vec3 x(4.0f * u(rng), 0.2f * u(rng), 4.0f * u(rng));
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f * u(rng), 1.0f, 0.3f * u(rng)));
    glm::vec3 fast(0.0f), slow(0.0f);
    const bool hit = cache.lookup(x, n, fast);
    REQUIRE(hit == bruteForce(cache.records(), a, x, n, slow));
    if (!hit) continue;
    ++used;
    CHECK(fast == slow);
    CHECK(std::isfinite(fast.x));
  }
  CHECK(used > 200);
}
