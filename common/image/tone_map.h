// Display encoding for the viewing path (PNG): linear radiance -> exposure -> tone map ->
// sRGB transfer curve -> 8 bits, and the inverse sRGB decode used when a PNG is read back.
// EXR output never goes through here: it keeps linear radiance.
#pragma once

#include <cstdint>
#include <string_view>

namespace pr::image {

// Clamp: radiance above 1 saturates (exact for pictures already in [0, 1]).
// Reinhard: c / (1 + c) per channel (Reinhard et al. 2002, eq. 3, without the white point),
// which keeps detail in bright caustics and lights at the cost of dimming everything.
enum class ToneMap { Clamp, Reinhard };

std::string_view toneMapName(ToneMap toneMap);
// "clamp" | "reinhard"; anything else throws pr::InputError naming the value.
ToneMap parseToneMap(std::string_view name);

struct DisplaySettings {
  float exposureStops = 0.0f;  // radiance is multiplied by 2^exposureStops before the tone map
  ToneMap toneMap = ToneMap::Clamp;
};

// sRGB transfer curve (IEC 61966-2-1): linear in [0, 1] to encoded in [0, 1] and back.
float srgbEncode(float linear);
float srgbDecode(float encoded);

// One channel of linear radiance to an 8-bit display value: exposure, tone map, sRGB, round.
uint8_t toDisplay8(float radiance, const DisplaySettings& settings);

}  // namespace pr::image
