// Seeded Perlin gradient noise and its fractal sum (fBm), the height function of the
// `landscape` scene (Jensen 1996, figure 4: "a fractal landscape created via discrete sampling
// of Perlin's noise function"). Used only by the scene generator, never at render time.
#pragma once

#include <array>
#include <cstdint>

namespace pr::scenegen {

// 2D gradient noise (Perlin 1985, with the quintic fade of Perlin 2002). Unit-length
// gradients in 8 directions, so |noise| <= sqrt(2)/2 (reached only at a cell centre with all
// four gradients pointing at it) and noise is 0 at every integer lattice point.
class PerlinNoise {
 public:
  explicit PerlinNoise(uint64_t seed);

  float noise(float x, float y) const;

  // Fractal Brownian motion: sum over octaves of gain^i * noise(lacunarity^i * p), divided by
  // the sum of gain^i so the result keeps noise's bound: |fbm| <= sqrt(2)/2.
  float fbm(float x, float y, int octaves, float lacunarity = 2.0f, float gain = 0.5f) const;

  static constexpr float kBound = 0.70710678f;

 private:
  int hash(int x, int y) const;
  std::array<uint8_t, 512> perm_;  // a seeded permutation of 0..255, repeated once
};

}  // namespace pr::scenegen
