// Image-based lighting (see image_based_light.h): SH irradiance, GGX-prefiltered levels and the
// split-sum albedo table. Deterministic: the same environment gives the same tables on every
// run and PE, so images stay bit-identical across sort points and P.
#include "raster/stages/image_based_light.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>

#include "common/scene/microfacet.h"
#include "common/scene/tangent_frame.h"
#include "common/util/unit_table.h"

namespace pr::raster {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr int kLevels = 6;            // roughness 0, 0.2, ..., 1
constexpr int kBaseWidth = 128;       // level 0; each rougher level halves, down to 16 x 8
constexpr int kPrefilterSamples = 64;
constexpr int kAlbedoSize = 32;

// Van der Corput radical inverse: a fixed low-discrepancy sequence (Hammersley points).
float radicalInverse(uint32_t bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return float(bits) * 2.3283064365386963e-10f;
}

glm::vec3 directionOf(float u, float v) {
  const float phi = 2.0f * kPi * u, theta = kPi * v;
  const float s = std::sin(theta);
  return {s * std::cos(phi), std::cos(theta), s * std::sin(phi)};
}

glm::vec2 texelOf(const glm::vec3& d) {
  float u = std::atan2(d.z, d.x) / (2.0f * kPi);
  u -= std::floor(u);
  return {u, std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi};
}

// Real SH basis functions, bands 0-2, at unit direction d.
std::array<float, 9> shBasis(const glm::vec3& d) {
  return {0.282095f,
          0.488603f * d.y, 0.488603f * d.z, 0.488603f * d.x,
          1.092548f * d.x * d.y, 1.092548f * d.y * d.z, 0.315392f * (3.0f * d.z * d.z - 1.0f),
          1.092548f * d.x * d.z, 0.546274f * (d.x * d.x - d.y * d.y)};
}

using AlbedoTable = UnitTable<glm::vec2, kAlbedoSize>;

AlbedoTable integrateSpecularAlbedo() {
  AlbedoTable table{};
  constexpr int kSamples = 256;
  for (int r = 0; r < kAlbedoSize; ++r) {
    const float roughness = std::max(AlbedoTable::coordinate(r), 0.045f);
    const float alpha = roughness * roughness, k = 0.5f * alpha;
    for (int c = 0; c < kAlbedoSize; ++c) {
      const float NdotV = std::max(AlbedoTable::coordinate(c), 1.0e-3f);
      const glm::vec3 V(std::sqrt(1.0f - NdotV * NdotV), 0.0f, NdotV);
      glm::vec2 sum(0.0f);
      for (int i = 0; i < kSamples; ++i) {
        const glm::vec3 H = scene::ggxNormal(alpha, (float(i) + 0.5f) / kSamples, radicalInverse(uint32_t(i)));
        const float VdotH = glm::dot(V, H);
        const glm::vec3 L = 2.0f * VdotH * H - V;
        if (L.z <= 0.0f || VdotH <= 0.0f) continue;
        // pdf(L) = D NdotH / (4 VdotH), so f cos / pdf = G VdotH / (NdotH NdotV) times F.
        const float g = (L.z / (L.z * (1.0f - k) + k)) * (NdotV / (NdotV * (1.0f - k) + k));
        const float vis = g * VdotH / (H.z * NdotV);
        const float fc = std::pow(1.0f - VdotH, 5.0f);
        sum += glm::vec2((1.0f - fc) * vis, fc * vis);
      }
      table.at(r, c) = sum / float(kSamples);
    }
  }
  return table;
}

}  // namespace

glm::vec2 specularAlbedo(float NdotV, float roughness) {
  static const AlbedoTable table = integrateSpecularAlbedo();
  return table.lookup(NdotV, roughness);
}

ImageBasedLight::ImageBasedLight(const scene::Environment& env) {
  if (env.isUniform()) {
    // Exact: irradiance pi L from every normal, and L along every reflection.
    uniform_ = true;
    uniformRadiance_ = env.radiance(glm::vec3(0.0f, 1.0f, 0.0f));
    return;
  }
  // SH projection on an equal-area grid (uniform in cos theta and phi): every cell has solid
  // angle 4 pi / N, so a constant projects exactly.
  constexpr int kRows = 64, kColumns = 128;
  std::array<glm::dvec3, 9> coefficients{};
  for (int i = 0; i < kRows; ++i) {
    const float cosT = 1.0f - 2.0f * (float(i) + 0.5f) / kRows;
    const float sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
    for (int j = 0; j < kColumns; ++j) {
      const float phi = 2.0f * kPi * (float(j) + 0.5f) / kColumns;
      const glm::vec3 d(sinT * std::cos(phi), cosT, sinT * std::sin(phi));
      const glm::dvec3 l(env.radiance(d));
      const std::array<float, 9> y = shBasis(d);
      for (int k = 0; k < 9; ++k) coefficients[size_t(k)] += l * double(y[size_t(k)]);
    }
  }
  // Convolution with the clamped cosine: A0 = pi, A1 = 2 pi / 3, A2 = pi / 4.
  constexpr double kBand[9] = {kPi, 2 * kPi / 3, 2 * kPi / 3, 2 * kPi / 3, kPi / 4, kPi / 4, kPi / 4, kPi / 4, kPi / 4};
  const double cell = 4.0 * kPi / double(kRows * kColumns);
  for (int k = 0; k < 9; ++k) sh_[size_t(k)] = glm::vec3(coefficients[size_t(k)] * cell * kBand[k]);

  // Prefiltered levels: N = V = R, GGX lobe of the level's roughness, radiance-weighted by
  // NdotL (Karis 2013). Level 0 is the environment itself, 4 samples per texel.
  levels_.resize(kLevels);
  for (int lv = 0; lv < kLevels; ++lv) {
    Level& level = levels_[size_t(lv)];
    level.width = std::max(kBaseWidth >> lv, 16);
    level.height = level.width / 2;
    level.texels.resize(size_t(level.width) * size_t(level.height));
    const float roughness = float(lv) / float(kLevels - 1);
    const float alpha = roughness * roughness;
    for (int y = 0; y < level.height; ++y) {
      for (int x = 0; x < level.width; ++x) {
        glm::vec3 sum(0.0f);
        if (lv == 0) {
          for (int s = 0; s < 4; ++s)
            sum += env.radiance(directionOf((float(x) + 0.25f + 0.5f * float(s & 1)) / float(level.width),
                                            (float(y) + 0.25f + 0.5f * float(s >> 1)) / float(level.height)));
          level.texels[size_t(y * level.width + x)] = sum * 0.25f;
          continue;
        }
        const glm::vec3 n = directionOf((float(x) + 0.5f) / float(level.width), (float(y) + 0.5f) / float(level.height));
        glm::vec3 s, t;
        scene::orthonormalBasis(n, s, t);
        float weight = 0.0f;
        for (int i = 0; i < kPrefilterSamples; ++i) {
          const glm::vec3 h = scene::ggxNormal(alpha, (float(i) + 0.5f) / kPrefilterSamples, radicalInverse(uint32_t(i)));
          const glm::vec3 hw = h.x * s + h.y * t + h.z * n;
          const glm::vec3 l = 2.0f * glm::dot(n, hw) * hw - n;
          const float NdotL = glm::dot(n, l);
          if (NdotL <= 0.0f) continue;
          sum += env.radiance(l) * NdotL;
          weight += NdotL;
        }
        level.texels[size_t(y * level.width + x)] = weight > 0.0f ? sum / weight : glm::vec3(0.0f);
      }
    }
  }
}

std::shared_ptr<const ImageBasedLight> ImageBasedLight::of(const std::shared_ptr<const scene::Environment>& env) {
  if (!env) return nullptr;
  // Prefiltering an image environment costs far more than a frame: keep the last few.
  static std::mutex mutex;
  static std::vector<std::pair<std::weak_ptr<const scene::Environment>, std::shared_ptr<const ImageBasedLight>>> cache;
  std::lock_guard lock(mutex);
  std::erase_if(cache, [](const auto& entry) { return entry.first.expired(); });
  for (const auto& [key, value] : cache)
    if (key.lock() == env) return value;
  auto built = std::make_shared<const ImageBasedLight>(*env);
  cache.emplace_back(env, built);
  return built;
}

glm::vec3 ImageBasedLight::irradiance(const glm::vec3& n) const {
  if (uniform_) return kPi * uniformRadiance_;
  const std::array<float, 9> y = shBasis(n);
  glm::vec3 e(0.0f);
  for (int k = 0; k < 9; ++k) e += sh_[size_t(k)] * y[size_t(k)];
  return glm::max(e, glm::vec3(0.0f));
}

glm::vec3 ImageBasedLight::sampleLevel(const Level& level, const glm::vec3& dir) const {
  const glm::vec2 uv = texelOf(dir);
  const float x = uv.x * float(level.width) - 0.5f, y = std::clamp(uv.y * float(level.height) - 0.5f, 0.0f, float(level.height - 1));
  const int x0 = int(std::floor(x)), y0 = std::min(int(y), level.height - 1);
  const int y1 = std::min(y0 + 1, level.height - 1);
  const float fx = x - float(x0), fy = y - float(y0);
  auto at = [&](int xi, int yi) {
    xi = ((xi % level.width) + level.width) % level.width;  // wraps around in longitude
    return level.texels[size_t(yi * level.width + xi)];
  };
  return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), fx), glm::mix(at(x0, y1), at(x0 + 1, y1), fx), fy);
}

glm::vec3 ImageBasedLight::prefiltered(const glm::vec3& r, float roughness) const {
  if (uniform_) return uniformRadiance_;
  const float f = std::clamp(roughness, 0.0f, 1.0f) * float(kLevels - 1);
  const int l0 = std::min(int(f), kLevels - 2);
  return glm::mix(sampleLevel(levels_[size_t(l0)], r), sampleLevel(levels_[size_t(l0 + 1)], r), f - float(l0));
}

}  // namespace pr::raster
