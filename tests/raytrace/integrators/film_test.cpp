// Film: fixed-point accumulation must make the sum independent of the order of contributions
// (what bit-identical images across PEs rest on) and must drop non-finite values.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include <doctest/doctest.h>

#include "raytrace/integrators/film.h"

using pr::rt::Film;

TEST_CASE("Film: sums are identical for any order of contributions") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(0.0f, 10.0f);
  std::vector<glm::vec3> contributions(2000);
  for (glm::vec3& c : contributions) c = {value(rng), value(rng) * 1e-3f, value(rng) * 1e3f};
  Film a(1, 1, 1), b(1, 1, 1);
  for (const glm::vec3& c : contributions) a.add(0, c);
  std::shuffle(contributions.begin(), contributions.end(), rng);
  for (const glm::vec3& c : contributions) b.add(0, c);
  for (int ch = 0; ch < 3; ++ch) CHECK(a.raw(0, ch) == b.raw(0, ch));
  // Float summation in these two orders would differ in the last bits; the film must not.
  CHECK(a.toImage().pixels[0] == b.toImage().pixels[0]);
}

TEST_CASE("Film: concurrent adds from several threads give the sequential sum") {
  Film seq(4, 1, 2), par(4, 1, 2);
  for (int i = 0; i < 4000; ++i) seq.add(uint32_t(i % 4), glm::vec3(0.001f * float(i % 97)));
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = t; i < 4000; i += 4) par.add(uint32_t(i % 4), glm::vec3(0.001f * float(i % 97)));
    });
  for (std::thread& t : threads) t.join();
  for (uint32_t p = 0; p < 4; ++p) CHECK(seq.raw(p, 1) == par.raw(p, 1));
}

TEST_CASE("Film: mean over spp, non-finite and negative values dropped") {
  Film film(2, 1, 4);
  film.add(0, glm::vec3(1.0f, 2.0f, 4.0f));
  film.add(0, glm::vec3(std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -1.0f));
  film.add(1, glm::vec3(0.5f));
  const pr::image::Image img = film.toImage();
  CHECK(img.pixels[0].x == doctest::Approx(0.25));
  CHECK(img.pixels[0].y == doctest::Approx(0.5));
  CHECK(img.pixels[0].z == doctest::Approx(1.0));
  CHECK(img.pixels[1].x == doctest::Approx(0.125));
  for (const glm::vec3& p : img.pixels) CHECK((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
}
