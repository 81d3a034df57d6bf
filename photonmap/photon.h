// Photon: one stored packet of flux of Jensen's photon map (pass 1 writes them, the kd-tree
// holds them in heap order, the density estimate reads them). Compact, 20 bytes: position
// (3 floats), power as Ward's shared-exponent RGBE (4 bytes), the incoming direction as an
// octahedral unit vector (2 x 8 bits), the kd split axis with the map kind, and the bounce count.
// Seed: "Global Illumination in Complex Scenes using Photon Maps", section 2.3 (28 bytes there).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace pr::pm {

// Which map a photon belongs to (the two maps of the seed's section 2.1).
enum class PhotonMapKind : std::uint8_t { Global = 0, Caustic = 1 };

// ---- power: Ward's RGBE ("Real Pixels", Graphics Gems II) ---------------------------------
// Three 8-bit mantissas share the exponent of the largest channel. Encoding rounds to nearest
// (Ward truncates and decodes at +0.5; that turns a zero channel into a small positive one,
// i.e. adds energy, which a photon map must not). Bound: every channel is off by at most half a
// mantissa step, and the largest channel's mantissa is at least 127.75 steps (128, or 127.75
// to 128 when it rounded up to 256 and moved to the next exponent), so the error of each
// channel is at most 0.5 / 127.75 = 1/255.5 (0.39 %) of the largest channel. Zero stays
// exactly zero; negative and NaN channels are stored as zero (a photon's power is never
// negative); values beyond 2^127 saturate, values below 2^-128 underflow to zero.
using Rgbe = std::array<std::uint8_t, 4>;

inline Rgbe packRgbe(const glm::vec3& power) {
  float c[3];
  for (int i = 0; i < 3; ++i) c[i] = power[i] > 0.0f ? std::min(power[i], 3.0e38f) : 0.0f;  // NaN fails > 0
  const float v = std::max(c[0], std::max(c[1], c[2]));
  if (!(v >= 0x1p-128f)) return {0, 0, 0, 0};
  int e = 0;
  std::frexp(v, &e);  // v = m 2^e, m in [0.5, 1)
  float scale = std::ldexp(1.0f, 8 - e);  // exact: the mantissas are c 2^(8-e), the largest in [128, 256)
  if (std::floor(v * scale + 0.5f) >= 256.0f) {  // the largest rounds up to 256: one exponent higher
    ++e;
    scale *= 0.5f;
  }
  if (e > 127) return {255, 255, 255, 255};
  Rgbe out;
  for (int i = 0; i < 3; ++i) out[i] = static_cast<std::uint8_t>(std::min(255.0f, std::floor(c[i] * scale + 0.5f)));
  out[3] = static_cast<std::uint8_t>(e + 128);
  return out;
}

inline glm::vec3 unpackRgbe(const Rgbe& rgbe) {
  if (rgbe[3] == 0) return glm::vec3(0.0f);
  const float f = std::ldexp(1.0f, static_cast<int>(rgbe[3]) - (128 + 8));
  return glm::vec3(rgbe[0] * f, rgbe[1] * f, rgbe[2] * f);
}

// ---- direction: octahedral unit vector, 2 x 8 bits (Cigolle et al., JCGT 3(2), 2014) -------
// Chosen over Jensen's (theta, phi) bytes: the octahedral cells are nearly equal in solid
// angle (theta/phi bytes crowd the poles and are coarsest at the equator, 180/256 by 360/256
// degrees), decoding needs no trigonometry or tables, and with the "precise" encoder below
// (of the four neighbouring grid points keep the one nearest the direction) the largest
// angular error over the sphere is about 0.6 degrees (tests/photonmap/photon_test.cpp measures
// it; the bound asserted there is 1 degree). Mapping: project onto |x|+|y|+|z| = 1, fold the
// lower half over the diagonals, quantise each coordinate of [-1, 1] to 255 steps (0 and 255
// are exactly -1 and +1).
using Octahedral = std::array<std::uint8_t, 2>;

namespace detail {
inline glm::vec3 octDecode(float u, float v) {
  glm::vec3 d(u, v, 1.0f - std::abs(u) - std::abs(v));
  if (d.z < 0.0f) {
    const float x = (1.0f - std::abs(d.y)) * (d.x >= 0.0f ? 1.0f : -1.0f);
    const float y = (1.0f - std::abs(d.x)) * (d.y >= 0.0f ? 1.0f : -1.0f);
    d.x = x;
    d.y = y;
  }
  return glm::normalize(d);
}
inline float octFromByte(int b) { return static_cast<float>(b) * (2.0f / 255.0f) - 1.0f; }
}  // namespace detail

inline glm::vec3 unpackDirection(const Octahedral& oct) {
  return detail::octDecode(detail::octFromByte(oct[0]), detail::octFromByte(oct[1]));
}

// dir need not be unit length; a zero or non-finite vector is stored as +z.
inline Octahedral packDirection(const glm::vec3& dir) {
  const float l1 = std::abs(dir.x) + std::abs(dir.y) + std::abs(dir.z);
  if (!(l1 > 0.0f) || !std::isfinite(l1)) return {128, 128};
  float u = dir.x / l1, v = dir.y / l1;
  if (dir.z < 0.0f) {
    const float fu = (1.0f - std::abs(v)) * (u >= 0.0f ? 1.0f : -1.0f);
    const float fv = (1.0f - std::abs(u)) * (v >= 0.0f ? 1.0f : -1.0f);
    u = fu;
    v = fv;
  }
  const glm::vec3 unit = dir / std::sqrt(glm::dot(dir, dir));
  const int bu = std::clamp(static_cast<int>(std::floor((u + 1.0f) * 127.5f)), 0, 254);
  const int bv = std::clamp(static_cast<int>(std::floor((v + 1.0f) * 127.5f)), 0, 254);
  Octahedral best{static_cast<std::uint8_t>(bu), static_cast<std::uint8_t>(bv)};
  float bestCos = -2.0f;
  for (int du = 0; du <= 1; ++du)
    for (int dv = 0; dv <= 1; ++dv) {
      const Octahedral c{static_cast<std::uint8_t>(bu + du), static_cast<std::uint8_t>(bv + dv)};
      const float cosAngle = glm::dot(unpackDirection(c), unit);
      if (cosAngle > bestCos) {
        bestCos = cosAngle;
        best = c;
      }
    }
  return best;
}

// ---- the stored photon ----------------------------------------------------------------------
// The kinds of reflection a photon's path took before it was stored, as bits: what splits the
// light a point receives into Jensen's terms - direct (no bounce), caustic (ideal specular
// bounces only), glossy-caustic (a glossy bounce but no diffuse one) and indirect (a diffuse
// bounce) - so each term reads only its own photons and no path is counted twice.
namespace PhotonPath {
inline constexpr std::uint8_t kDiffuse = 1;  // a Lambertian reflection
inline constexpr std::uint8_t kGlossy = 2;   // a rough specular, sheen or clear-coat reflection
}

// flags: bits 0-1 the kd-tree split axis of the node holding the photon (0 x, 1 y, 2 z; written
// by KdTree::build, meaningless before), bit 2 the map kind, bits 3-4 the PhotonPath bits.
// bounces: how many surface interactions the path had before this photon was stored (0 =
// direct light), saturating.
struct Photon {
  glm::vec3 position{0.0f};
  Rgbe power{0, 0, 0, 0};
  Octahedral direction{128, 128};  // wi: unit vector from the surface back towards where the photon came from
  std::uint8_t flags = 0;
  std::uint8_t bounces = 0;

  static Photon make(const glm::vec3& position, const glm::vec3& power, const glm::vec3& wi,
                     PhotonMapKind kind = PhotonMapKind::Global, int bounces = 0, std::uint8_t path = 0) {
    Photon p;
    p.position = position;
    p.power = packRgbe(power);
    p.direction = packDirection(wi);
    p.setKind(kind);
    p.bounces = static_cast<std::uint8_t>(std::clamp(bounces, 0, 255));
    p.flags = static_cast<std::uint8_t>(p.flags | ((path & 3u) << 3));
    return p;
  }

  glm::vec3 powerRgb() const { return unpackRgbe(power); }
  glm::vec3 incoming() const { return unpackDirection(direction); }
  int splitAxis() const { return flags & 3; }
  void setSplitAxis(int axis) { flags = static_cast<std::uint8_t>((flags & ~3u) | (static_cast<unsigned>(axis) & 3u)); }
  PhotonMapKind kind() const { return static_cast<PhotonMapKind>((flags >> 2) & 1u); }
  std::uint8_t path() const { return static_cast<std::uint8_t>((flags >> 3) & 3u); }
  void setKind(PhotonMapKind kind) {
    flags = static_cast<std::uint8_t>((flags & ~4u) | ((static_cast<unsigned>(kind) & 1u) << 2));
  }
};

static_assert(sizeof(Photon) <= 20, "a stored photon is at most 20 bytes (issue 10)");
static_assert(sizeof(Photon) == 20);

}  // namespace pr::pm
