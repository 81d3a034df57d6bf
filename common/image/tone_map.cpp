// Display encoding of linear radiance for PNG output (see tone_map.h): exposure in stops,
// a clamp or Reinhard tone map, the sRGB curve and rounding to 8 bits.
#include "common/image/tone_map.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/util/error.h"

namespace pr::image {

std::string_view toneMapName(ToneMap toneMap) {
  switch (toneMap) {
    case ToneMap::Clamp: return "clamp";
    case ToneMap::Reinhard: return "reinhard";
  }
  return "clamp";
}

ToneMap parseToneMap(std::string_view name) {
  if (name == "clamp") return ToneMap::Clamp;
  if (name == "reinhard") return ToneMap::Reinhard;
  throw InputError("unknown tone map '" + std::string(name) + "' (expected clamp or reinhard)");
}

// IEC 61966-2-1: a linear toe below 0.0031308 (slope 12.92), a 1/2.4 power above it.
float srgbEncode(float linear) {
  float c = std::clamp(linear, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// The exact inverse of srgbEncode; 0.04045 = 12.92 * 0.0031308 is where the pieces meet.
float srgbDecode(float encoded) {
  float c = std::clamp(encoded, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

uint8_t toDisplay8(float radiance, const DisplaySettings& settings) {
  // NaN (a bug upstream, not a colour) shows as black instead of an undefined cast.
  if (std::isnan(radiance)) return 0;
  float c = std::max(radiance, 0.0f) * std::exp2(settings.exposureStops);
  if (settings.toneMap == ToneMap::Reinhard) c = std::isinf(c) ? 1.0f : c / (1.0f + c);
  return static_cast<uint8_t>(std::lround(srgbEncode(c) * 255.0f));
}

}  // namespace pr::image
