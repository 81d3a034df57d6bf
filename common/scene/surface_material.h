// The material at one surface point as both renderer families shade it: a glTF Material with
// its textures, vertex colour and normal maps applied. The rasterizer's shading stage and the
// ray tracers' BSDF both start from resolveMaterial, so a material feature is read once, the
// same way, in every method; they differ only in how they integrate the light.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "common/scene/scene.h"

namespace pr::scene {

// What the renderer knows about the point: interpolated vertex attributes.
struct SurfaceGeometry {
  glm::vec2 uv{0.0f};
  glm::vec4 colour{1.0f};           // COLOR_0, 1 without
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  // unit shading normal
  glm::vec4 tangent{0.0f};          // xyz tangent, w handedness; zero = no tangent frame
};

struct SurfaceMaterial {
  glm::vec3 baseColor{1.0f};  // factor * texture * COLOR_0, clamped to [0, 1]
  float opacity = 1.0f;       // base alpha (factor * texture * COLOR_0 alpha)
  float metallic = 1.0f;
  float roughness = 1.0f;
  // KHR_materials_specular
  float specular = 1.0f;
  glm::vec3 specularColor{1.0f};
  float transmission = 0.0f;
  float ior = 1.5f;
  glm::vec3 emission{0.0f};  // nits, emissive texture applied
  // KHR_materials_clearcoat
  float clearcoat = 0.0f;
  float clearcoatRoughness = 0.0f;
  glm::vec3 clearcoatNormal{0.0f, 0.0f, 1.0f};
  // KHR_materials_sheen
  glm::vec3 sheenColor{0.0f};
  float sheenRoughness = 0.0f;
  // KHR_materials_anisotropy: strength, and the direction in the tangent plane as (cos, sin)
  // of its angle from the uv tangent (rotation and texture applied)
  float anisotropy = 0.0f;
  glm::vec2 anisotropyDirection{1.0f, 0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  // the shading normal, normal map applied

  // F0 and F90 of the dielectric (non-metal) Fresnel term, KHR_materials_specular:
  // F0 = min(((ior - 1) / (ior + 1))^2 specularColor, 1) specular, F90 = specular. F0 is
  // computed once by resolveMaterial (shading reads it per light).
  glm::vec3 f0{0.04f};
  glm::vec3 dielectricF0() const { return f0; }
  float dielectricF90() const { return specular; }
  bool hasSheen() const { return sheenColor.x > 0.0f || sheenColor.y > 0.0f || sheenColor.z > 0.0f; }
};

// textures = false reads the factors alone (the plan's textures off); each texture slot not
// read is then counted in *skipped when given.
SurfaceMaterial resolveMaterial(const Scene& scene, uint32_t material, const SurfaceGeometry& at, bool textures = true,
                                uint64_t* skipped = nullptr);

// Whether resolveMaterial reads a texture for this material.
bool usesTextures(const Material& material);

// Whether a material's alpha can make a surface point invisible (alphaMode MASK or BLEND).
bool alphaCuts(const Material& material);
// The base alpha at a point: baseColorFactor.a * base-colour texture alpha * COLOR_0 alpha.
float opacityAt(const Scene& scene, uint32_t material, glm::vec2 uv, glm::vec4 colour);
// Whether the surface is there at a point of this opacity: OPAQUE always; MASK when the opacity
// reaches alphaCutoff; BLEND with probability opacity (stochastic transparency, Enderton et al.
// 2010), decided by xi in [0, 1), which each family draws from what it is sampling.
bool alphaPasses(const Material& material, float opacity, float xi);

}  // namespace pr::scene
