// Texture sampling for shading (every renderer calls it per shading point): glTF sampler wrap
// modes, nearest or bilinear filtering, and sRGB decoding of colour slots before filtering
// (filtering encoded values would darken edges; glTF 2.0 spec, 3.8.4 and 3.9.2).
#include "common/scene/texture.h"

#include <array>
#include <cmath>

namespace pr::scene {

namespace {

// sRGB transfer function (IEC 61966-2-1), tabulated for the 256 possible 8-bit codes.
const std::array<float, 256>& srgbToLinearTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      float c = float(i) / 255.0f;
      t[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }
    return t;
  }();
  return table;
}

// Maps an integer texel coordinate (possibly outside [0, n)) into the image.
int wrapIndex(int i, int n, Wrap wrap) {
  switch (wrap) {
    case Wrap::Repeat: {
      int m = i % n;
      return m < 0 ? m + n : m;
    }
    case Wrap::ClampToEdge:
      return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case Wrap::MirroredRepeat: {
      // Period 2n: 0..n-1 forwards, then n-1..0 backwards.
      int period = 2 * n;
      int m = i % period;
      if (m < 0) m += period;
      return m < n ? m : period - 1 - m;
    }
  }
  return 0;
}

}  // namespace

glm::vec4 Texture::sample(glm::vec2 uv, bool srgb) const {
  if (width <= 0 || height <= 0 || rgba8.empty()) return glm::vec4(1.0f);
  const auto& lut = srgbToLinearTable();
  auto texel = [&](int x, int y) {
    const uint8_t* p = &rgba8[(size_t(wrapIndex(y, height, sampler.wrapT)) * width +
                               size_t(wrapIndex(x, width, sampler.wrapS))) * 4];
    if (srgb) return glm::vec4(lut[p[0]], lut[p[1]], lut[p[2]], float(p[3]) / 255.0f);
    return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
  };
  // Texel centres sit at (i + 0.5) / size in UV; a non-finite uv (degenerate interpolation)
  // samples texel 0 rather than indexing with garbage.
  // Huge coordinates are clamped so the integer texel index cannot overflow (2^24 is where
  // float UVs stop resolving texels anyway).
  constexpr float kMaxCoord = 16777216.0f;
  float x = std::isfinite(uv.x) ? glm::clamp(uv.x * float(width), -kMaxCoord, kMaxCoord) : 0.0f;
  float y = std::isfinite(uv.y) ? glm::clamp(uv.y * float(height), -kMaxCoord, kMaxCoord) : 0.0f;
  // magFilter picks nearest or bilinear; without ray differentials the footprint is unknown,
  // so there is no mip-mapping and minFilter is kept for reference only.
  if (sampler.magFilter == Filter::Nearest) {
    return texel(int(std::floor(x)), int(std::floor(y)));
  }
  x -= 0.5f;
  y -= 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  int x0 = int(fx), y0 = int(fy);
  float tx = x - fx, ty = y - fy;
  glm::vec4 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), tx);
  glm::vec4 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), tx);
  return glm::mix(top, bottom, ty);
}

}  // namespace pr::scene
