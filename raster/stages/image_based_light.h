// Image-based lighting for the rasterizer: the environment the ray tracers sample, turned into
// what a glTF viewer shades with - diffuse irradiance as nine spherical-harmonic coefficients
// (Ramamoorthi & Hanrahan 2001) and specular radiance prefiltered by roughness for the
// split-sum approximation (Karis 2013: prefiltered radiance along the reflection times a
// directional-albedo table of the BRDF). No occlusion: the rasterizer has no visibility
// queries, so a surface sees the whole environment (the ray tracers shadow it).
// Built once per environment (cached while it lives), then read by every PE's shading stage.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/environment.h"

namespace pr::raster {

class ImageBasedLight {
 public:
  explicit ImageBasedLight(const scene::Environment& environment);
  // The one for this environment, prefiltered on first use and shared while it lives.
  static std::shared_ptr<const ImageBasedLight> of(const std::shared_ptr<const scene::Environment>& environment);

  // Irradiance (lux) on a surface with unit normal n, from the whole sphere of directions.
  glm::vec3 irradiance(const glm::vec3& n) const;
  // Radiance of the environment along unit direction r, averaged over a GGX lobe of this
  // roughness (the split sum's first factor).
  glm::vec3 prefiltered(const glm::vec3& r, float roughness) const;

 private:
  struct Level {
    int width = 0, height = 0;
    std::vector<glm::vec3> texels;  // equirectangular, row 0 = +y
  };
  glm::vec3 sampleLevel(const Level& level, const glm::vec3& dir) const;

  bool uniform_ = false;
  glm::vec3 uniformRadiance_{0.0f};
  std::array<glm::vec3, 9> sh_{};  // irradiance-convolved SH coefficients
  std::vector<Level> levels_;      // roughness k / (levels - 1)
};

// The split sum's second factor: the GGX BRDF's directional albedo for view cosine NdotV
// and roughness as (A, B), so that specular = prefiltered * (F0 A + F90 B). The geometry term
// is the shading stage's Schlick-GGX (k = alpha / 2); integrated numerically on first use.
glm::vec2 specularAlbedo(float NdotV, float roughness);

}  // namespace pr::raster
