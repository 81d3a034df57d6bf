// Seeded 2D Perlin gradient noise and fBm for the landscape terrain (see noise.h).
#include "tools/scenegen/noise.h"

#include <cmath>
#include <numeric>
#include <utility>

#include "tools/scenegen/random.h"

namespace pr::scenegen {
namespace {

// Quintic fade 6t^5 - 15t^4 + 10t^3 (Perlin 2002): zero first and second derivatives at the
// lattice, so the terrain's normals are continuous across cells.
float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

float lerp(float a, float b, float t) { return a + t * (b - a); }

// Dot of the unit gradient number h (8 directions, 45 degrees apart) with (x, y).
float gradDot(int h, float x, float y) {
  constexpr float d = 0.70710678f;  // cos 45 degrees
  switch (h & 7) {
    case 0: return x;
    case 1: return -x;
    case 2: return y;
    case 3: return -y;
    case 4: return d * (x + y);
    case 5: return d * (x - y);
    case 6: return d * (-x + y);
    default: return d * (-x - y);
  }
}

}  // namespace

PerlinNoise::PerlinNoise(uint64_t seed) {
  // Fisher-Yates with our own generator: std::shuffle's output is implementation-defined.
  std::array<uint8_t, 256> p;
  std::iota(p.begin(), p.end(), uint8_t{0});
  SplitMix64 rng(seed);
  for (uint32_t i = 255; i > 0; --i) std::swap(p[i], p[rng.below(i + 1)]);
  for (int i = 0; i < 512; ++i) perm_[i] = p[i & 255];
}

int PerlinNoise::hash(int x, int y) const { return perm_[perm_[x & 255] + (y & 255)]; }

float PerlinNoise::noise(float x, float y) const {
  const float fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const float dx = x - fx, dy = y - fy;
  const float n00 = gradDot(hash(ix, iy), dx, dy);
  const float n10 = gradDot(hash(ix + 1, iy), dx - 1.0f, dy);
  const float n01 = gradDot(hash(ix, iy + 1), dx, dy - 1.0f);
  const float n11 = gradDot(hash(ix + 1, iy + 1), dx - 1.0f, dy - 1.0f);
  const float u = fade(dx), v = fade(dy);
  return lerp(lerp(n00, n10, u), lerp(n01, n11, u), v);
}

float PerlinNoise::fbm(float x, float y, int octaves, float lacunarity, float gain) const {
  float sum = 0.0f, amplitude = 1.0f, norm = 0.0f, frequency = 1.0f;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * noise(x * frequency, y * frequency);
    norm += amplitude;
    amplitude *= gain;
    frequency *= lacunarity;
  }
  return norm > 0.0f ? sum / norm : 0.0f;
}

}  // namespace pr::scenegen
