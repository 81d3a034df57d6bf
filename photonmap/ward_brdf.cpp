// The Ward anisotropic BRDF (see ward_brdf.h).
#include "photonmap/ward_brdf.h"

#include <algorithm>
#include <cmath>

namespace pr::pm {

namespace {
using rt::kPi;
constexpr float kMinAlpha = 1.0e-3f;
}  // namespace

glm::vec3 evalWard(const WardLobe& lobe, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  const glm::vec3 h = glm::normalize(wo + wi);
  if (h.z <= 0.0f) return glm::vec3(0.0f);
  const float ax = lobe.alphaX, ay = lobe.alphaY;
  // tan^2(theta_h) (cos^2 phi / ax^2 + sin^2 phi / ay^2) = (hx^2 / ax^2 + hy^2 / ay^2) / hz^2
  const float e = ((h.x * h.x) / (ax * ax) + (h.y * h.y) / (ay * ay)) / (h.z * h.z);
  const float d = std::exp(-e) / (4.0f * kPi * ax * ay * std::sqrt(wo.z * wi.z));
  return rt::fresnelSchlick(lobe.f0, glm::dot(h, wo), lobe.f90) * d;
}

rt::BsdfSample sampleWard(const WardLobe& lobe, const glm::vec3& wo, float u, float v) {
  rt::BsdfSample s;
  if (wo.z <= 0.0f) return s;
  const float ax = lobe.alphaX, ay = lobe.alphaY;
  // phi_h = atan(ay / ax tan(2 pi v)), in v's quadrant (Walter 2005, eq. 6).
  const float twoPiV = 2.0f * kPi * v;
  const float phi = std::atan2(ay * std::sin(twoPiV), ax * std::cos(twoPiV));
  const float c = std::cos(phi), sn = std::sin(phi);
  const float a = c * c / (ax * ax) + sn * sn / (ay * ay);
  const float tan2 = -std::log(std::max(1.0f - u, 1.0e-12f)) / a;  // theta_h (eq. 7), 1 - u in (0, 1]
  const float cosH = 1.0f / std::sqrt(1.0f + tan2);
  const float sinH = std::sqrt(std::max(0.0f, 1.0f - cosH * cosH));
  const glm::vec3 h(sinH * c, sinH * sn, cosH);
  const float oh = glm::dot(wo, h);
  if (oh <= 0.0f) return s;
  s.wi = 2.0f * oh * h - wo;
  if (s.wi.z <= 0.0f) return s;
  const float ph = std::exp(-tan2 * a) / (kPi * ax * ay * cosH * cosH * cosH);
  s.pdf = ph / (4.0f * oh);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = rt::fresnelSchlick(lobe.f0, oh, lobe.f90) * (oh * cosH * cosH * cosH * std::sqrt(s.wi.z / wo.z));
  s.valid = rt::isFinite(s.weight);
  return s;
}

WardLobe wardLobe(const rt::ShadingMaterial& m) {
  WardLobe lobe;
  lobe.f0 = m.specularF0();
  lobe.f90 = m.specularF90();
  const float alpha = std::max(m.alpha, kMinAlpha);
  const float k = m.anisotropy * m.anisotropy;
  lobe.alphaX = alpha + (1.0f - alpha) * k;
  lobe.alphaY = alpha;
  return lobe;
}

}  // namespace pr::pm
