// The GGX microfacet distribution (Walter et al. 2007, "Microfacet models for refraction
// through rough surfaces"), in a local frame whose z is the surface normal: the terms every
// GGX lobe of both families is made of - the ray tracers' specular, glass and clear-coat lobes,
// the rasterizer's clear coat and its prefiltered environment.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

namespace pr::scene {

// Eq. 33: the normal distribution D at a microfacet normal with cosine cosH to the normal.
inline float ggxD(float alpha, float cosH) {
  if (cosH <= 0.0f) return 0.0f;
  const float a2 = alpha * alpha;
  const float d = cosH * cosH * (a2 - 1.0f) + 1.0f;
  return a2 / (std::numbers::pi_v<float> * d * d);
}

// Eq. 34: Smith's masking term for a direction with cosine c to the normal.
inline float ggxG1(float alpha, float c) {
  if (c <= 0.0f) return 0.0f;
  const float a2 = alpha * alpha;
  return 2.0f * c / (c + std::sqrt(a2 + (1.0f - a2) * c * c));
}

// Eq. 35: a microfacet normal with density D(h) h.z for (u, v) in [0, 1)^2:
// cos^2(theta_h) = (1 - u) / (1 + (alpha^2 - 1) u), phi_h = 2 pi v.
inline glm::vec3 ggxNormal(float alpha, float u, float v) {
  const float a2 = alpha * alpha;
  const float cos2 = (1.0f - u) / (1.0f + (a2 - 1.0f) * u);
  const float cosH = std::sqrt(std::clamp(cos2, 0.0f, 1.0f));
  const float sinH = std::sqrt(std::max(0.0f, 1.0f - cosH * cosH));
  const float phi = 2.0f * std::numbers::pi_v<float> * v;
  return {sinH * std::cos(phi), sinH * std::sin(phi), cosH};
}

}  // namespace pr::scene
