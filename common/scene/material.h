// Materials of the render-ready scene: glTF pbrMetallicRoughness plus the KHR extensions
// parrender honours (emissive_strength, transmission, ior, volume, anisotropy, specular,
// clearcoat, sheen, texture_transform).
// Colour factors are linear; textures keep their 8-bit texels and are decoded per slot
// (base colour and emissive are sRGB-encoded, every other slot is linear data).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

namespace pr::scene {

// A texture slot of a material: which texture, which UV transform (KHR_texture_transform).
struct TextureRef {
  int texture = -1;               // index into Scene::textures, -1 = none
  int texCoord = 0;               // UV set; parrender loads set 0 only
  glm::mat3 uvTransform{1.0f};    // applied to (u, v, 1): offset * rotation * scale
  bool present() const { return texture >= 0; }
  // The UV at which to sample the texture: uvTransform applied to (u, v, 1).
  glm::vec2 transformUv(glm::vec2 uv) const;
};

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// How a renderer should treat a material (for `info`, EffectAnalysis and integrators).
enum class MaterialKind : uint8_t { Diffuse, Specular, Glass, Emissive, Anisotropic };
std::string_view toString(MaterialKind kind);

struct Material {
  std::string name;
  // pbrMetallicRoughness
  glm::vec4 baseColorFactor{1.0f};
  TextureRef baseColorTexture;
  float metallicFactor = 1.0f;
  float roughnessFactor = 1.0f;
  TextureRef metallicRoughnessTexture;  // B = metallic, G = roughness (glTF)
  TextureRef normalTexture;
  float normalScale = 1.0f;
  // emission: emissiveFactor * emissiveStrength, in nits (cd/m^2), as glTF defines it
  glm::vec3 emissiveFactor{0.0f};
  float emissiveStrength = 1.0f;
  TextureRef emissiveTexture;
  // KHR_materials_transmission / ior / volume
  float transmissionFactor = 0.0f;
  TextureRef transmissionTexture;
  float ior = 1.5f;
  float thicknessFactor = 0.0f;  // 0 = thin-walled
  glm::vec3 attenuationColor{1.0f};
  float attenuationDistance = std::numeric_limits<float>::infinity();
  // KHR_materials_anisotropy
  float anisotropyStrength = 0.0f;
  float anisotropyRotation = 0.0f;  // radians
  TextureRef anisotropyTexture;     // RG = direction, B = strength (KHR_materials_anisotropy)
  // KHR_materials_specular: scales the dielectric Fresnel (F0 and F90) and tints its F0
  float specularFactor = 1.0f;
  TextureRef specularTexture;       // A = factor
  glm::vec3 specularColorFactor{1.0f};
  TextureRef specularColorTexture;  // RGB, sRGB-encoded
  // KHR_materials_clearcoat: a clear dielectric GGX layer (ior 1.5) over the material
  float clearcoatFactor = 0.0f;
  TextureRef clearcoatTexture;           // R = factor
  float clearcoatRoughnessFactor = 0.0f;
  TextureRef clearcoatRoughnessTexture;  // G = roughness
  TextureRef clearcoatNormalTexture;
  float clearcoatNormalScale = 1.0f;
  // KHR_materials_sheen: a Charlie-distribution retro-reflective layer (cloth, velvet)
  glm::vec3 sheenColorFactor{0.0f};
  TextureRef sheenColorTexture;      // RGB, sRGB-encoded
  float sheenRoughnessFactor = 0.0f;
  TextureRef sheenRoughnessTexture;  // A = roughness
  // core flags
  bool doubleSided = false;
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;

  glm::vec3 emission() const { return emissiveFactor * emissiveStrength; }
  bool isEmissive() const { return glm::any(glm::greaterThan(emission(), glm::vec3(0.0f))); }
  bool hasClearcoat() const { return clearcoatFactor > 0.0f; }
  bool hasSheen() const { return glm::any(glm::greaterThan(sheenColorFactor, glm::vec3(0.0f))); }
  // The dominant kind, in priority order emissive > glass > anisotropic > specular > diffuse.
  // Specular: a metal (metallic >= 0.5) with roughness < 0.2, i.e. a mirror-like lobe.
  MaterialKind kind() const;
};

}  // namespace pr::scene
