// Material classification: the one place that decides which kind a glTF material is, read by
// `parrender info`, EffectAnalysis (which effects a scene calls for) and the integrators.
#include "common/scene/material.h"

namespace pr::scene {

std::string_view toString(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::Diffuse: return "diffuse";
    case MaterialKind::Specular: return "specular";
    case MaterialKind::Glass: return "glass";
    case MaterialKind::Emissive: return "emissive";
    case MaterialKind::Anisotropic: return "anisotropic";
  }
  return "unknown";
}

glm::vec2 TextureRef::transformUv(glm::vec2 uv) const {
  return glm::vec2(uvTransform * glm::vec3(uv, 1.0f));
}

// Priority order: a light source first (it is sampled as a light whatever else it does), then
// transmission (needs refraction paths), then anisotropy (a lobe of its own), then mirrors.
MaterialKind Material::kind() const {
  if (isEmissive()) return MaterialKind::Emissive;
  if (transmissionFactor > 0.0f) return MaterialKind::Glass;
  if (anisotropyStrength > 0.0f) return MaterialKind::Anisotropic;
  // A metal with a narrow lobe reflects a sharp image of its surroundings: treat as specular.
  if (metallicFactor >= 0.5f && roughnessFactor < 0.2f) return MaterialKind::Specular;
  return MaterialKind::Diffuse;
}

}  // namespace pr::scene
