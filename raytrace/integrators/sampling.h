// Counter-based random numbers and the sample warps of the integrators. A number is a pure
// function of (seed, pixel, sample, depth, dimension): any PE, in any order, draws the same
// numbers for the same path vertex, which is what makes every tracer and every P give the
// same image (shared/DESIGN.md rule 3). Warps: stratified pixel samples, cosine hemisphere,
// uniform triangle, GGX half vectors.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "common/scene/tangent_frame.h"
#include "common/util/hash.h"

namespace pr::rt {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
// The largest float below 1: a sample in [0, 1) never reaches 1 (24-bit mantissa).
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

using pr::mix64;  // common/util/hash.h

// Dimensions drawn at one path vertex; each use has its own so no two correlate.
namespace Dim {
inline constexpr uint32_t kPixelX = 0, kPixelY = 1;
inline constexpr uint32_t kLightPick = 2, kLightU = 3, kLightV = 4;
inline constexpr uint32_t kLobe = 5, kBsdfU = 6, kBsdfV = 7;
inline constexpr uint32_t kRoulette = 8;
inline constexpr uint32_t kEnvU = 9, kEnvV = 10;  // the environment light's sample
// Further area-light samples at one vertex (IntegratorContext::directLight), three each.
inline constexpr uint32_t kLightExtra = 16;
// First dimension free for an integrator's own draws (photonmap: gather and glossy rays),
// above the extra area-light samples of up to 64 per vertex (16 + 3 x 63 = 205).
inline constexpr uint32_t kIntegratorOwn = 256;
}  // namespace Dim

// A uniform number in [0, 1) for one (seed, pixel, sample, depth, dimension).
inline float sample1D(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t depth, uint32_t dim) {
  uint64_t h = mix64(seed ^ 0x9e3779b97f4a7c15ull);
  h = mix64(h ^ (uint64_t(pixel) << 32 | sample));
  h = mix64(h ^ (uint64_t(depth) << 32 | dim));
  // Top 24 bits: exactly representable, so the result is < 1.
  return float(h >> 40) * 0x1p-24f;
}

// The stratum grid for spp samples: nx * ny == spp with nx the largest divisor <= sqrt(spp),
// so every sample has its own cell and the cells tile the pixel (unbiased for any spp).
inline glm::ivec2 strataFor(int spp) {
  int nx = std::max(1, int(std::sqrt(double(spp))));
  while (nx > 1 && spp % nx != 0) --nx;
  return {nx, std::max(1, spp / nx)};
}

// Jittered position in [0,1)^2 of sample `s` of a pixel, in its own stratum.
inline glm::vec2 stratifiedPixelSample(int s, int spp, float u, float v) {
  const glm::ivec2 n = strataFor(spp);
  const float x = (float(s % n.x) + u) / float(n.x);
  const float y = (float(s / n.x) + v) / float(n.y);
  return {std::min(x, kOneMinusEpsilon), std::min(y, kOneMinusEpsilon)};
}

// An orthonormal basis around unit n (Duff et al. 2017, "Building an orthonormal basis, revisited").
struct Frame {
  glm::vec3 s, t, n;
  explicit Frame(const glm::vec3& normal) : n(normal) { scene::orthonormalBasis(n, s, t); }
  glm::vec3 toWorld(const glm::vec3& v) const { return v.x * s + v.y * t + v.z * n; }
  glm::vec3 toLocal(const glm::vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
};

// Cosine-weighted direction about +z (Malley's method); pdf = cos(theta) / pi.
inline glm::vec3 cosineHemisphere(float u, float v) {
  const float r = std::sqrt(u);
  const float phi = 2.0f * kPi * v;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u))};
}

// Uniform point on a triangle as barycentrics (b1, b2) (Shirley's square-root warp).
inline glm::vec2 uniformTriangle(float u, float v) {
  const float su = std::sqrt(u);
  return {su * (1.0f - v), su * v};
}

// Luminance of linear Rec. 709 RGB: the weight of a colour for light selection and roulette.
inline float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

inline float maxComponent(const glm::vec3& c) { return std::max(c.x, std::max(c.y, c.z)); }

// True when every component is finite: contributions failing it are dropped, never stored.
inline bool isFinite(const glm::vec3& c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); }

}  // namespace pr::rt
