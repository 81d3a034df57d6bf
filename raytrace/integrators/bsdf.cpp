// Material evaluation and the BSDF of the integrators (see bsdf.h). Runs on the PE shading a
// hit; reads only the Scene's materials and textures. Microfacet terms after Walter et al.
// 2007, "Microfacet models for refraction through rough surfaces" (GGX D, Smith G1 eq. 34).
#include "raytrace/integrators/bsdf.h"

#include <algorithm>
#include <cmath>

#include "raytrace/integrators/sampling.h"

namespace pr::rt {

namespace {

// Walter et al. eq. 33: the GGX normal distribution, h in the local frame.
float ggxD(float alpha, float cosH) {
  if (cosH <= 0.0f) return 0.0f;
  const float a2 = alpha * alpha;
  const float d = cosH * cosH * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}

// Walter et al. eq. 34: Smith's masking term for GGX, direction with cosine `c` to the normal.
float ggxG1(float alpha, float c) {
  if (c <= 0.0f) return 0.0f;
  const float a2 = alpha * alpha;
  return 2.0f * c / (c + std::sqrt(a2 + (1.0f - a2) * c * c));
}

// Pdf of the GGX reflection sample: D(h) cos(h) for h, and dwh/dwi = 1 / (4 wo.h).
float ggxPdf(float alpha, const glm::vec3& wo, const glm::vec3& wi) {
  const glm::vec3 h = glm::normalize(wo + wi);
  const float oh = glm::dot(wo, h);
  if (oh <= 0.0f) return 0.0f;
  return ggxD(alpha, h.z) * h.z / (4.0f * oh);
}

// wo reflected about a GGX half vector: cos^2(theta_h) = (1 - u) / (1 + (alpha^2 - 1) u)
// (Walter et al. eq. 35), phi_h = 2 pi v.
glm::vec3 ggxReflection(float alpha, const glm::vec3& wo, float u, float v) {
  const float a2 = alpha * alpha;
  const float cos2 = (1.0f - u) / (1.0f + (a2 - 1.0f) * u);
  const float cosH = std::sqrt(std::clamp(cos2, 0.0f, 1.0f));
  const float sinH = std::sqrt(std::max(0.0f, 1.0f - cosH * cosH));
  const float phi = 2.0f * kPi * v;
  const glm::vec3 h(sinH * std::cos(phi), sinH * std::sin(phi), cosH);
  return 2.0f * glm::dot(wo, h) * h - wo;
}

glm::vec4 textureLookup(const scene::Scene& scene, const scene::TextureRef& ref, glm::vec2 uv, bool srgb) {
  if (!ref.present() || size_t(ref.texture) >= scene.textures.size()) return glm::vec4(1.0f);
  return scene.textures[size_t(ref.texture)].sample(ref.transformUv(uv), srgb);
}

}  // namespace

bool usesTextures(const scene::Material& mat) {
  return mat.baseColorTexture.present() || mat.metallicRoughnessTexture.present() || mat.transmissionTexture.present() ||
         (mat.isEmissive() && mat.emissiveTexture.present()) || (mat.anisotropyStrength > 0.0f && mat.anisotropyTexture.present());
}

ShadingMaterial evalMaterial(const scene::Scene& scene, const SurfaceInteraction& si, bool textures) {
  const scene::Material& mat = scene.materials[si.material];
  auto textureOr = [&](const scene::Scene& sc, const scene::TextureRef& ref, glm::vec2 uv, bool srgb) {
    return textures ? textureLookup(sc, ref, uv, srgb) : glm::vec4(1.0f);
  };
  ShadingMaterial m;
  const glm::vec4 base = mat.baseColorFactor * textureOr(scene, mat.baseColorTexture, si.uv, true);
  m.baseColor = glm::clamp(glm::vec3(base), 0.0f, 1.0f);
  const glm::vec4 mr = textureOr(scene, mat.metallicRoughnessTexture, si.uv, false);
  m.metallic = std::clamp(mat.metallicFactor * mr.z, 0.0f, 1.0f);
  m.roughness = std::clamp(mat.roughnessFactor * mr.y, 0.0f, 1.0f);
  m.alpha = m.roughness * m.roughness;
  m.transmission = std::clamp(mat.transmissionFactor * textureOr(scene, mat.transmissionTexture, si.uv, false).x, 0.0f, 1.0f);
  // An ior of 1 (or a nonsensical one) would make refraction the identity or undefined.
  m.ior = std::isfinite(mat.ior) && mat.ior > 1.0001f ? mat.ior : 1.5f;
  if (mat.isEmissive())
    m.emission = glm::max(mat.emission() * glm::vec3(textureOr(scene, mat.emissiveTexture, si.uv, true)), glm::vec3(0.0f));
  m.doubleSided = mat.doubleSided;
  if (mat.anisotropyStrength > 0.0f) {
    // The texture's RG is a tangent-space direction in [-1, 1]^2 and B scales the strength;
    // the rotation turns the direction counter-clockwise (KHR_materials_anisotropy).
    glm::vec2 dir(1.0f, 0.0f);
    float strength = mat.anisotropyStrength;
    if (textures && mat.anisotropyTexture.present()) {
      const glm::vec4 t = textureOr(scene, mat.anisotropyTexture, si.uv, false);
      const glm::vec2 d = glm::vec2(t) * 2.0f - 1.0f;
      if (glm::dot(d, d) > 1.0e-8f) dir = glm::normalize(d);
      strength *= t.z;
    }
    const float c = std::cos(mat.anisotropyRotation), s = std::sin(mat.anisotropyRotation);
    m.anisotropyDirection = glm::vec2(c * dir.x - s * dir.y, s * dir.x + c * dir.y);
    m.anisotropy = std::clamp(strength, 0.0f, 1.0f);
  }
  return m;
}

glm::vec3 emittedRadiance(const ShadingMaterial& m, const SurfaceInteraction& si) {
  return (si.frontFace || m.doubleSided) ? m.emission : glm::vec3(0.0f);
}

glm::vec3 fresnelSchlick(const glm::vec3& f0, float cosTheta) {
  const float c = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float c2 = c * c;
  return f0 + (glm::vec3(1.0f) - f0) * (c2 * c2 * c);
}

float fresnelDielectric(float cosI, float eta) {
  cosI = std::clamp(cosI, 0.0f, 1.0f);
  const float sin2T = (1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return 1.0f;  // total internal reflection
  const float cosT = std::sqrt(1.0f - sin2T);
  const float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  const float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5f * (rs * rs + rp * rp);
}

bool refractDirection(const glm::vec3& w, const glm::vec3& n, float eta, glm::vec3& wt) {
  const float cosI = glm::dot(w, n);
  const float sin2T = std::max(0.0f, 1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return false;
  const float cosT = std::sqrt(1.0f - sin2T);
  wt = glm::normalize(-w / eta + (cosI / eta - cosT) * n);
  return true;
}

float specularProbability(const ShadingMaterial& m, float cosO) {
  if (!m.hasSpecular()) return 0.0f;
  const float ws = luminance(fresnelSchlick(m.specularF0(), cosO));
  const float wd = luminance(m.diffuseColor());
  return ws + wd > 0.0f ? ws / (ws + wd) : 0.0f;
}

glm::vec3 evalGlossy(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f || !m.hasSpecular() || m.deltaSpecular()) return glm::vec3(0.0f);
  const glm::vec3 h = glm::normalize(wo + wi);
  const float d = ggxD(m.alpha, h.z);
  const float g = ggxG1(m.alpha, wo.z) * ggxG1(m.alpha, wi.z);
  return fresnelSchlick(m.specularF0(), glm::dot(wo, h)) * (d * g / (4.0f * wo.z * wi.z));
}

BsdfSample sampleGlossy(const ShadingMaterial& m, const glm::vec3& wo, float u, float v) {
  BsdfSample s;
  if (wo.z <= 0.0f || !m.hasSpecular() || m.deltaSpecular()) return s;
  s.wi = ggxReflection(m.alpha, wo, u, v);
  if (s.wi.z <= 0.0f) return s;
  s.pdf = ggxPdf(m.alpha, wo, s.wi);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = evalGlossy(m, wo, s.wi) * (s.wi.z / s.pdf);
  s.valid = isFinite(s.weight);
  return s;
}

glm::vec3 evalOpaque(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  return m.diffuseColor() * kInvPi + evalGlossy(m, wo, wi);
}

float pdfOpaque(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const float ps = specularProbability(m, wo.z);
  float pdf = (1.0f - ps) * wi.z * kInvPi;
  if (ps > 0.0f && !m.deltaSpecular()) pdf += ps * ggxPdf(m.alpha, wo, wi);
  return pdf;
}

BsdfSample sampleOpaque(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v) {
  BsdfSample s;
  if (wo.z <= 0.0f) return s;
  const float ps = specularProbability(m, wo.z);
  if (lobe < ps) {
    if (m.deltaSpecular()) {
      // Perfect mirror: f cos / pdf = F / (probability of this lobe).
      s.wi = glm::vec3(-wo.x, -wo.y, wo.z);
      s.weight = fresnelSchlick(m.specularF0(), wo.z) / ps;
      s.delta = true;
      s.valid = true;
      return s;
    }
    s.wi = ggxReflection(m.alpha, wo, u, v);
  } else {
    s.wi = cosineHemisphere(u, v);
  }
  if (s.wi.z <= 0.0f) return s;
  s.pdf = pdfOpaque(m, wo, s.wi);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = evalOpaque(m, wo, s.wi) * (s.wi.z / s.pdf);
  s.valid = isFinite(s.weight);
  return s;
}

}  // namespace pr::rt
