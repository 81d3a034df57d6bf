// Sheen and clear-coat lobes (see material_layers.h).
#include "common/scene/material_layers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "common/scene/microfacet.h"
#include "common/util/unit_table.h"

namespace pr::scene {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
// Below this a the Charlie lobe's exponent 1/a overflows sin^(1/a) to a spike nothing samples.
constexpr float kMinSheenAlpha = 0.07f * 0.07f;

float sheenAlpha(float roughness) { return std::max(roughness * roughness, kMinSheenAlpha); }

// E_sheen on a grid of NdotV x roughness, integrated once by the midpoint rule in (cos theta, phi).
constexpr int kAlbedoSize = 32;
using AlbedoTable = UnitTable<float, kAlbedoSize>;

AlbedoTable integrateAlbedo() {
  AlbedoTable table{};
  constexpr int kTheta = 96, kPhi = 48;
  for (int r = 0; r < kAlbedoSize; ++r) {
    const float roughness = AlbedoTable::coordinate(r);
    for (int v = 0; v < kAlbedoSize; ++v) {
      const float cosV = std::max(AlbedoTable::coordinate(v), 1.0e-3f);
      const float sinV = std::sqrt(1.0f - cosV * cosV);
      double sum = 0.0;
      for (int i = 0; i < kTheta; ++i) {
        const float cosL = (float(i) + 0.5f) / float(kTheta);
        const float sinL = std::sqrt(1.0f - cosL * cosL);
        for (int j = 0; j < kPhi; ++j) {
          const float phi = kPi * (float(j) + 0.5f) / float(kPhi);  // symmetric in phi: half the circle, twice
          // V = (sinV, 0, cosV), L = (sinL cos phi, sinL sin phi, cosL), H = normalize(V + L).
          const float hx = sinV + sinL * std::cos(phi), hy = sinL * std::sin(phi), hz = cosV + cosL;
          const float cosH = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
          sum += double(sheenLobe(roughness, cosH, cosL, cosV) * cosL);
        }
      }
      table.at(r, v) = float(sum * (2.0 * kPi / kPhi) / kTheta);
    }
  }
  return table;
}

}  // namespace

float sheenLobe(float roughness, float NdotH, float NdotL, float NdotV) {
  if (NdotL <= 0.0f || NdotV <= 0.0f) return 0.0f;
  const float a = sheenAlpha(roughness);
  const float sin2 = std::max(0.0f, 1.0f - NdotH * NdotH);
  const float d = (2.0f + 1.0f / a) * std::pow(sin2, 0.5f / a) / (2.0f * kPi);
  const float vis = 1.0f / (4.0f * (NdotL + NdotV - NdotL * NdotV));
  return d * vis;
}

float sheenAlbedo(float roughness, float NdotV) {
  static const AlbedoTable table = integrateAlbedo();
  return std::clamp(table.lookup(NdotV, roughness), 0.0f, 1.0f);
}

float coatFresnel(float cosTheta) {
  const float c = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float c2 = c * c;
  return 0.04f + 0.96f * (c2 * c2 * c);
}

float coatAlpha(float roughness) { return std::max(roughness * roughness, 2.0e-3f); }

float coatLobe(float roughness, float NdotH, float NdotL, float NdotV, float VdotH) {
  if (NdotL <= 0.0f || NdotV <= 0.0f || NdotH <= 0.0f) return 0.0f;
  const float alpha = coatAlpha(roughness);
  const float G = ggxG1(alpha, NdotL) * ggxG1(alpha, NdotV);
  return ggxD(alpha, NdotH) * G * coatFresnel(VdotH) / (4.0f * NdotL * NdotV);
}

}  // namespace pr::scene
