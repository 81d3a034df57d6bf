// Tests of common/image/tone_map.cpp: the sRGB curve's known points and inverse, the two
// tone maps, exposure in stops, and the parsing of tone map names.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "common/image/tone_map.h"
#include "common/util/error.h"

using namespace pr::image;

TEST_CASE("ToneMap: sRGB curve hits its known points and decode inverts encode") {
  CHECK(srgbEncode(0.0f) == 0.0f);
  CHECK(srgbEncode(1.0f) == doctest::Approx(1.0f));
  CHECK(srgbEncode(0.002f) == doctest::Approx(12.92f * 0.002f));  // linear toe
  CHECK(srgbEncode(0.18f) == doctest::Approx(0.46135f).epsilon(1e-4));  // 18% grey
  for (float v : {0.0f, 0.001f, 0.0031308f, 0.05f, 0.18f, 0.5f, 0.9f, 1.0f})
    CHECK(srgbDecode(srgbEncode(v)) == doctest::Approx(v).epsilon(1e-5));
}

TEST_CASE("ToneMap: clamp, Reinhard and exposure give the expected 8-bit values") {
  DisplaySettings clamp;
  CHECK(toDisplay8(0.0f, clamp) == 0);
  CHECK(toDisplay8(1.0f, clamp) == 255);
  CHECK(toDisplay8(7.0f, clamp) == 255);
  CHECK(toDisplay8(-1.0f, clamp) == 0);
  CHECK(toDisplay8(std::numeric_limits<float>::quiet_NaN(), clamp) == 0);
  // 0.18 -> sRGB 0.46135 -> 117.6 -> 118.
  CHECK(toDisplay8(0.18f, clamp) == 118);

  DisplaySettings reinhard{0.0f, ToneMap::Reinhard};
  // 1 / (1 + 1) = 0.5 -> sRGB 0.73536 -> 187.5 -> 188.
  CHECK(toDisplay8(1.0f, reinhard) == 188);
  CHECK(toDisplay8(1e6f, reinhard) == 255);
  CHECK(toDisplay8(std::numeric_limits<float>::infinity(), reinhard) == 255);

  DisplaySettings brighter{1.0f, ToneMap::Clamp};  // one stop: x2
  CHECK(toDisplay8(0.09f, brighter) == toDisplay8(0.18f, clamp));
}

TEST_CASE("ToneMap: names parse and unknown names are InputErrors") {
  CHECK(parseToneMap("clamp") == ToneMap::Clamp);
  CHECK(parseToneMap("reinhard") == ToneMap::Reinhard);
  CHECK(toneMapName(ToneMap::Reinhard) == "reinhard");
  CHECK_THROWS_AS(parseToneMap("filmic"), pr::InputError);
}
