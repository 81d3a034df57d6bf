// Lights of the render-ready scene: KHR_lights_punctual lights in world space, and the
// emissive triangles that act as area lights.
// Units are glTF's photometric units, which are mutually consistent, so no conversion is
// needed: point/spot intensity in candela (lm/sr), directional in lux (lm/m^2), emission in
// nits (cd/m^2). Irradiance from a point light is intensity / d^2 lux.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

namespace pr::scene {

enum class LightType : uint8_t { Point, Spot, Directional };
std::string_view toString(LightType type);

struct PunctualLight {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};            // world space (point, spot)
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // world space, unit, the way light travels (spot, directional)
  glm::vec3 color{1.0f};               // linear RGB
  float intensity = 1.0f;              // cd (point, spot) or lux (directional)
  float range = std::numeric_limits<float>::infinity();
  float innerConeAngle = 0.0f;         // radians (spot)
  float outerConeAngle = 0.7853982f;   // radians, pi/4 default (spot)
};

// KHR_lights_punctual's recommended range window: clamp(1 - (d / range)^4, 0, 1)^2, smooth to
// zero at `range`; 1 for an infinite or unset range. Multiplies the inverse-square falloff.
// The one definition both families and the photon tracer light with.
inline float rangeWindow(float distance, float range) {
  if (!std::isfinite(range) || range <= 0.0f) return 1.0f;
  const float r = distance / range;
  const float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
  return w * w;
}

// KHR_lights_punctual spot attenuation along the unit direction `towardsPoint` (from the light):
// t^2 with t rising linearly in the cosine from the outer cone (0) to the inner one (1).
inline float spotFactor(const PunctualLight& light, const glm::vec3& towardsPoint) {
  const float cosOuter = std::cos(light.outerConeAngle);
  const float cosInner = std::cos(light.innerConeAngle);
  const float scale = 1.0f / std::max(1.0e-3f, cosInner - cosOuter);
  const float t = std::clamp((glm::dot(light.direction, towardsPoint) - cosOuter) * scale, 0.0f, 1.0f);
  return t * t;
}

// An emissive triangle used as an area light (its emission comes from its material).
struct AreaLight {
  uint32_t triangle = 0;  // index into Scene::triangles
  float area = 0.0f;      // world-space m^2
};

}  // namespace pr::scene
