// Resolving a material at a surface point (see surface_material.h). Runs on the PE that shades
// the point; reads only the Scene's materials and textures.
#include "common/scene/surface_material.h"

#include <algorithm>
#include <cmath>

#include "common/scene/tangent_frame.h"

namespace pr::scene {

namespace {

// ((ior - 1) / (ior + 1))^2 specularColor, at most 1, times specular; in double, so that
// ior 1.5 gives exactly 0.04f, the constant of glTF's core model.
glm::vec3 dielectricF0(float ior, glm::vec3 specularColor, float specular) {
  const double r = (double(ior) - 1.0) / (double(ior) + 1.0);
  return glm::min(glm::vec3(float(r * r)) * specularColor, glm::vec3(1.0f)) * specular;
}

}  // namespace

bool usesTextures(const Material& m) {
  return m.baseColorTexture.present() || m.metallicRoughnessTexture.present() || m.normalTexture.present() ||
         m.transmissionTexture.present() || (m.isEmissive() && m.emissiveTexture.present()) ||
         (m.anisotropyStrength > 0.0f && m.anisotropyTexture.present()) || m.specularTexture.present() ||
         m.specularColorTexture.present() ||
         (m.hasClearcoat() && (m.clearcoatTexture.present() || m.clearcoatRoughnessTexture.present() ||
                               m.clearcoatNormalTexture.present())) ||
         (m.hasSheen() && (m.sheenColorTexture.present() || m.sheenRoughnessTexture.present()));
}

bool alphaCuts(const Material& m) { return m.alphaMode != AlphaMode::Opaque; }

float opacityAt(const Scene& scene, uint32_t material, glm::vec2 uv, glm::vec4 colour) {
  const Material& m = scene.materials[material];
  float a = m.baseColorFactor.w * colour.w;
  if (m.baseColorTexture.present() && size_t(m.baseColorTexture.texture) < scene.textures.size())
    a *= scene.textures[size_t(m.baseColorTexture.texture)].sample(m.baseColorTexture.transformUv(uv), true).w;
  return std::clamp(a, 0.0f, 1.0f);
}

bool alphaPasses(const Material& m, float opacity, float xi) {
  switch (m.alphaMode) {
    case AlphaMode::Opaque: return true;
    case AlphaMode::Mask: return opacity >= m.alphaCutoff;
    case AlphaMode::Blend: return xi < opacity;
  }
  return true;
}

SurfaceMaterial resolveMaterial(const Scene& scene, uint32_t material, const SurfaceGeometry& at, bool textures,
                                uint64_t* skipped) {
  const Material& mat = scene.materials[material];
  // One slot's texel, or 1 when the slot is empty or the plan skips textures.
  auto slot = [&](const TextureRef& ref, bool srgb) {
    if (!ref.present() || size_t(ref.texture) >= scene.textures.size()) return glm::vec4(1.0f);
    if (!textures) {
      if (skipped) ++*skipped;
      return glm::vec4(1.0f);
    }
    return scene.textures[size_t(ref.texture)].sample(ref.transformUv(at.uv), srgb);
  };
  // A normal map bends the shading normal in the point's tangent frame (none without tangents).
  auto mapped = [&](const TextureRef& ref, float scale) {
    if (!ref.present() || at.tangent == glm::vec4(0.0f)) return at.normal;
    const glm::vec4 texel = slot(ref, false);
    return textures ? perturbNormal(at.normal, at.tangent, glm::vec3(texel), scale) : at.normal;
  };
  SurfaceMaterial m;
  const glm::vec4 base = mat.baseColorFactor * slot(mat.baseColorTexture, true) * at.colour;
  m.baseColor = glm::clamp(glm::vec3(base), 0.0f, 1.0f);
  m.opacity = std::clamp(base.w, 0.0f, 1.0f);
  const glm::vec4 mr = slot(mat.metallicRoughnessTexture, false);
  m.metallic = std::clamp(mat.metallicFactor * mr.z, 0.0f, 1.0f);
  m.roughness = std::clamp(mat.roughnessFactor * mr.y, 0.0f, 1.0f);
  m.specular = std::clamp(mat.specularFactor * slot(mat.specularTexture, false).w, 0.0f, 1.0f);
  m.specularColor = glm::max(mat.specularColorFactor * glm::vec3(slot(mat.specularColorTexture, true)), glm::vec3(0.0f));
  m.transmission = std::clamp(mat.transmissionFactor * slot(mat.transmissionTexture, false).x, 0.0f, 1.0f);
  m.ior = std::isfinite(mat.ior) && mat.ior >= 1.0f ? mat.ior : 1.5f;
  m.f0 = dielectricF0(m.ior, m.specularColor, m.specular);
  if (mat.isEmissive()) m.emission = glm::max(mat.emission() * glm::vec3(slot(mat.emissiveTexture, true)), glm::vec3(0.0f));
  m.normal = mapped(mat.normalTexture, mat.normalScale);
  if (mat.hasClearcoat()) {
    m.clearcoat = std::clamp(mat.clearcoatFactor * slot(mat.clearcoatTexture, false).x, 0.0f, 1.0f);
    m.clearcoatRoughness = std::clamp(mat.clearcoatRoughnessFactor * slot(mat.clearcoatRoughnessTexture, false).y, 0.0f, 1.0f);
    // Without a normal map of its own the coat follows the geometry, not the base's map.
    m.clearcoatNormal = mapped(mat.clearcoatNormalTexture, mat.clearcoatNormalScale);
  }
  if (mat.hasSheen()) {
    m.sheenColor = glm::clamp(mat.sheenColorFactor * glm::vec3(slot(mat.sheenColorTexture, true)), 0.0f, 1.0f);
    m.sheenRoughness = std::clamp(mat.sheenRoughnessFactor * slot(mat.sheenRoughnessTexture, false).w, 0.0f, 1.0f);
  }
  if (mat.anisotropyStrength > 0.0f) {
    // The texture's RG is a tangent-space direction in [-1, 1]^2 and B scales the strength;
    // the rotation turns the direction counter-clockwise (KHR_materials_anisotropy).
    glm::vec2 dir(1.0f, 0.0f);
    float strength = mat.anisotropyStrength;
    if (mat.anisotropyTexture.present()) {
      const glm::vec4 t = slot(mat.anisotropyTexture, false);
      if (textures) {
        const glm::vec2 d = glm::vec2(t) * 2.0f - 1.0f;
        if (glm::dot(d, d) > 1.0e-8f) dir = glm::normalize(d);
        strength *= t.z;
      }
    }
    const float c = std::cos(mat.anisotropyRotation), s = std::sin(mat.anisotropyRotation);
    m.anisotropyDirection = glm::vec2(c * dir.x - s * dir.y, s * dir.x + c * dir.y);
    m.anisotropy = std::clamp(strength, 0.0f, 1.0f);
  }
  return m;
}

}  // namespace pr::scene
