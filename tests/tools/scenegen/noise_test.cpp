// Tests of tools/scenegen/noise.cpp, the landscape's height function: gradient noise is zero
// on the lattice, bounded by sqrt(2)/2, continuous, and a function of the seed alone.
#include <doctest/doctest.h>

#include <cmath>

#include "tools/scenegen/noise.h"

using pr::scenegen::PerlinNoise;

TEST_CASE("PerlinNoise: zero at every integer lattice point") {
  PerlinNoise noise(7);
  for (int y = -20; y <= 20; y += 3)
    for (int x = -20; x <= 20; x += 3) CHECK(noise.noise(float(x), float(y)) == 0.0f);
}

TEST_CASE("PerlinNoise: same seed same values, other seed other values") {
  PerlinNoise a(1), b(1), c(2);
  int differing = 0;
  for (int i = 0; i < 200; ++i) {
    float x = 0.37f * i - 13.1f, y = 0.71f * i + 2.3f;
    CHECK(a.noise(x, y) == b.noise(x, y));
    CHECK(a.fbm(x, y, 6) == b.fbm(x, y, 6));
    differing += a.noise(x, y) != c.noise(x, y);
  }
  CHECK(differing > 150);
}

TEST_CASE("PerlinNoise: noise and fBm stay within sqrt(2)/2 and are not flat") {
  PerlinNoise noise(3);
  float lo = 0.0f, hi = 0.0f, fbmMax = 0.0f;
  for (int j = 0; j < 300; ++j)
    for (int i = 0; i < 300; ++i) {
      float x = i * 0.0437f - 5.0f, y = j * 0.0391f - 4.0f;
      float n = noise.noise(x, y);
      lo = std::min(lo, n), hi = std::max(hi, n);
      fbmMax = std::max(fbmMax, std::abs(noise.fbm(x, y, 8)));
    }
  CHECK(lo >= -PerlinNoise::kBound - 1e-6f);
  CHECK(hi <= PerlinNoise::kBound + 1e-6f);
  CHECK(fbmMax <= PerlinNoise::kBound + 1e-6f);
  // A broken hash or gradient table would give a flat or tiny field.
  CHECK(hi - lo > 0.5f);
}

TEST_CASE("PerlinNoise: continuous, including across cell borders") {
  PerlinNoise noise(11);
  // The gradient of one octave is at most about 2 (unit gradients, fade slope <= 1.875), so
  // a step of 1e-3 changes the value by well under 1e-2.
  for (int i = 0; i < 400; ++i) {
    float x = -3.0f + i * 0.0151f, y = 1.0f - i * 0.0097f;
    CHECK(std::abs(noise.noise(x + 1e-3f, y) - noise.noise(x, y)) < 1e-2f);
    CHECK(std::abs(noise.noise(x, y + 1e-3f) - noise.noise(x, y)) < 1e-2f);
  }
  CHECK(std::abs(noise.noise(2.0f - 1e-4f, 0.5f) - noise.noise(2.0f + 1e-4f, 0.5f)) < 1e-3f);
}
