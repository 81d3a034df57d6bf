// Material evaluation and the BSDF of the integrators (see bsdf.h). Runs on the PE shading a
// hit; reads only the Scene's materials and textures. Microfacet terms after Walter et al.
// 2007, "Microfacet models for refraction through rough surfaces" (GGX D, Smith G1 eq. 34).
#include "raytrace/integrators/bsdf.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/scene/material_layers.h"
#include "common/scene/microfacet.h"
#include "common/scene/surface_material.h"
#include "raytrace/integrators/sampling.h"

namespace pr::rt {

namespace {

using scene::ggxD;
using scene::ggxG1;

// Pdf of the GGX reflection sample: D(h) cos(h) for h, and dwh/dwi = 1 / (4 wo.h).
float ggxPdf(float alpha, const glm::vec3& wo, const glm::vec3& wi) {
  const glm::vec3 h = glm::normalize(wo + wi);
  const float oh = glm::dot(wo, h);
  if (oh <= 0.0f) return 0.0f;
  return ggxD(alpha, h.z) * h.z / (4.0f * oh);
}

// wo reflected about a GGX microfacet normal.
glm::vec3 ggxReflection(float alpha, const glm::vec3& wo, float u, float v) {
  const glm::vec3 h = scene::ggxNormal(alpha, u, v);
  return 2.0f * glm::dot(wo, h) * h - wo;
}

// Anisotropic GGX (Heitz 2014, "Understanding the masking-shadowing function"): roughness ax
// along the local x axis (the anisotropy direction, ShadingFrame), ay along y.
float ggxDAniso(float ax, float ay, const glm::vec3& h) {
  if (h.z <= 0.0f) return 0.0f;
  const float x = h.x / ax, y = h.y / ay;
  const float d = x * x + y * y + h.z * h.z;
  return 1.0f / (kPi * ax * ay * d * d);
}

float ggxG1Aniso(float ax, float ay, const glm::vec3& w) {
  if (w.z <= 0.0f) return 0.0f;
  const float t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z);
  return 2.0f / (1.0f + std::sqrt(1.0f + t2));
}

// A microfacet normal with density D(h) h.z: a slope of the alpha = 1 distribution
// (tan^2 theta = u / (1 - u), phi = 2 pi v) stretched by (ax, ay).
glm::vec3 ggxNormalAniso(float ax, float ay, float u, float v) {
  const float tanTheta = std::sqrt(u / std::max(1.0f - u, 1.0e-7f));
  const float phi = 2.0f * kPi * v;
  return glm::normalize(glm::vec3(-ax * tanTheta * std::cos(phi), -ay * tanTheta * std::sin(phi), 1.0f));
}

// The material's glossy lobe: isotropic GGX, or anisotropic when KHR_materials_anisotropy
// gives it a strength (alpha along the direction = mix(alpha, 1, strength^2), the extension's
// mapping).
struct GlossyLobe {
  float ax, ay;
  bool anisotropic;
  explicit GlossyLobe(const ShadingMaterial& m)
      : ax(m.anisotropy > 0.0f ? m.alpha + (1.0f - m.alpha) * m.anisotropy * m.anisotropy : m.alpha),
        ay(m.alpha),
        anisotropic(m.anisotropy > 0.0f) {}
  float d(const glm::vec3& h) const { return anisotropic ? ggxDAniso(ax, ay, h) : ggxD(ay, h.z); }
  float g1(const glm::vec3& w) const { return anisotropic ? ggxG1Aniso(ax, ay, w) : ggxG1(ay, w.z); }
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const {
    if (!anisotropic) return ggxPdf(ay, wo, wi);
    const glm::vec3 h = glm::normalize(wo + wi);
    const float oh = glm::dot(wo, h);
    return oh > 0.0f ? ggxDAniso(ax, ay, h) * h.z / (4.0f * oh) : 0.0f;
  }
  glm::vec3 reflect(const glm::vec3& wo, float u, float v) const {
    if (!anisotropic) return ggxReflection(ay, wo, u, v);
    const glm::vec3 h = ggxNormalAniso(ax, ay, u, v);
    return 2.0f * glm::dot(wo, h) * h - wo;
  }
};

// A normal map can tilt the normal so far that the mirror direction of wo about it points into
// the surface (a flat plate mapped to look like a sphere, seen near the sphere's rim), where
// every reflection would be lost and a metal turns black. The normal is then bent to the half
// vector of wo and that direction lifted just above the geometric plane (as Unreal's and
// Falcor's normal-map fixes do). In the geometric front's convention, as makeInteraction's.
glm::vec3 keepReflectionAbove(const glm::vec3& n, const SurfaceInteraction& si) {
  constexpr float kLift = 0.01f;
  const glm::vec3 w = si.frontFace ? si.wo : -si.wo;
  const glm::vec3& ng = si.geometricNormal;
  if (!(glm::dot(w, ng) > 0.0f)) return n;
  const glm::vec3 r = 2.0f * glm::dot(w, n) * n - w;
  const float above = glm::dot(r, ng);
  if (above >= kLift) return n;
  const glm::vec3 lifted = glm::normalize(r + ng * (kLift - above));
  const glm::vec3 h = w + lifted;
  const float len = glm::length(h);
  return len > 1.0e-6f && std::isfinite(len) ? h / len : n;
}

}  // namespace

ShadingMaterial evalMaterial(const scene::Scene& scene, const SurfaceInteraction& si, bool textures) {
  const scene::Material& mat = scene.materials[si.material];
  scene::SurfaceGeometry at;
  at.uv = si.uv;
  at.colour = si.colour;
  at.normal = si.shadingNormal;
  at.tangent = si.tangent;
  const scene::SurfaceMaterial r = scene::resolveMaterial(scene, si.material, at, textures);
  ShadingMaterial m;
  m.baseColor = r.baseColor;
  m.metallic = r.metallic;
  m.roughness = r.roughness;
  m.alpha = m.roughness * m.roughness;
  m.transmission = r.transmission;
  // Refraction with an ior of 1 (or a nonsensical one) would be the identity or undefined;
  // the Fresnel terms below use the material's own ior.
  m.ior = std::isfinite(mat.ior) && mat.ior > 1.0001f ? mat.ior : 1.5f;
  m.emission = r.emission;
  m.doubleSided = mat.doubleSided;
  m.anisotropy = r.anisotropy;
  m.anisotropyDirection = r.anisotropyDirection;
  m.dielectricF0 = r.dielectricF0();
  m.dielectricF90 = r.dielectricF90();
  // A normal map may bend the normal below the geometric surface; shading then keeps the
  // interpolated one, as makeInteraction keeps the geometric side.
  m.normal = glm::dot(r.normal, si.geometricNormal) > 0.0f ? r.normal : si.shadingNormal;
  if (m.normal != si.shadingNormal) m.normal = keepReflectionAbove(m.normal, si);
  m.sheenColor = r.sheenColor;
  m.sheenRoughness = r.sheenRoughness;
  m.clearcoat = r.clearcoat;
  m.clearcoatRoughness = r.clearcoatRoughness;
  if (mat.thicknessFactor > 0.0f) {
    m.thinWalled = false;
    const float d = mat.attenuationDistance;
    if (std::isfinite(d) && d > 0.0f)
      for (int c = 0; c < 3; ++c)
        m.attenuation[c] = -std::log(std::clamp(mat.attenuationColor[c], 1.0e-30f, 1.0f)) / d;
  }
  m.clearcoatNormalWorld = glm::dot(r.clearcoatNormal, si.geometricNormal) > 0.0f ? r.clearcoatNormal : si.shadingNormal;
  return m;
}

glm::vec3 volumeTransmittance(const ShadingMaterial& m, const SurfaceInteraction& si, const Ray& ray) {
  if (m.thinWalled || si.frontFace || !(m.transmission > 0.0f)) return glm::vec3(1.0f);
  const float distance = si.t * glm::length(ray.direction);
  glm::vec3 t(1.0f);
  for (int c = 0; c < 3; ++c) {
    const float optical = m.attenuation[c] * distance;  // both finite and >= 0
    t[c] = optical > 69.0f ? 0.0f : std::exp(-optical);  // exp(-69) ~ 1e-30
  }
  return t;
}

glm::vec3 emittedRadiance(const ShadingMaterial& m, const SurfaceInteraction& si) {
  return (si.frontFace || m.doubleSided) ? m.emission : glm::vec3(0.0f);
}

glm::vec3 fresnelSchlick(const glm::vec3& f0, float cosTheta, float f90) {
  const float c = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float c2 = c * c;
  return f0 + (glm::vec3(f90) - f0) * (c2 * c2 * c);
}

glm::vec3 ShadingMaterial::specularFresnel(float cosTheta) const {
  return fresnelSchlick(specularF0(), cosTheta, specularF90());
}

float ShadingMaterial::diffuseFresnelScale(float cosH) const {
  return 1.0f - maxComponent(fresnelSchlick(dielectricF0, cosH, dielectricF90));
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
  const float ws = luminance(m.specularFresnel(cosO));
  const float wd = luminance(m.diffuseColor());
  return ws + wd > 0.0f ? ws / (ws + wd) : 0.0f;
}

glm::vec3 evalGlossy(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f || !m.hasSpecular() || m.deltaSpecular()) return glm::vec3(0.0f);
  const glm::vec3 h = glm::normalize(wo + wi);
  const GlossyLobe lobe(m);
  const float d = lobe.d(h);
  const float g = lobe.g1(wo) * lobe.g1(wi);
  return m.specularFresnel(glm::dot(wo, h)) * (d * g / (4.0f * wo.z * wi.z));
}

BsdfSample sampleGlossy(const ShadingMaterial& m, const glm::vec3& wo, float u, float v) {
  BsdfSample s;
  if (wo.z <= 0.0f || !m.hasSpecular() || m.deltaSpecular()) return s;
  const GlossyLobe lobe(m);
  s.wi = lobe.reflect(wo, u, v);
  if (s.wi.z <= 0.0f) return s;
  s.pdf = lobe.pdf(wo, s.wi);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = evalGlossy(m, wo, s.wi) * (s.wi.z / s.pdf);
  s.valid = isFinite(s.weight);
  return s;
}

namespace {

// The clear coat's share of the reflection towards wo (its Fresnel term times its factor).
float coatWeight(const ShadingMaterial& m, const glm::vec3& wo) {
  if (!m.hasClearcoat()) return 0.0f;
  return m.clearcoat * scene::coatFresnel(std::max(glm::dot(m.clearcoatNormal, wo), 0.0f));
}

// What the sheen leaves the base for the pair (wo, wi): the base loses the sheen's directional
// albedo, so the pair never reflects more than the base alone could.
float sheenScale(const ShadingMaterial& m, float cosO, float cosI) {
  const float r = m.sheenRoughness;
  return 1.0f - maxComponent(m.sheenColor) * std::max(scene::sheenAlbedo(r, cosO), scene::sheenAlbedo(r, cosI));
}

// The Lambertian base under the dielectric's Fresnel layer: diffuse / pi less what the layer
// reflects for the pair's half-vector.
glm::vec3 fresnelDiffuse(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  return m.diffuseColor() * (kInvPi * m.diffuseFresnelScale(glm::dot(wo, glm::normalize(wo + wi))));
}

// The Lambertian base as the layers leave it: less the Fresnel layer's, the sheen's and the coat's share.
glm::vec3 layeredDiffuse(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  const float sheen = m.hasSheen() ? sheenScale(m, wo.z, wi.z) : 1.0f;
  return fresnelDiffuse(m, wo, wi) * (sheen * (1.0f - coatWeight(m, wo)));
}

// The cosine-weighted mean over wi of (1 - cos(wo, h))^5, Schlick's weight for the pair's
// half-vector, as a function of wo.z: tabulated once by quadrature (cos^2 theta_i and phi on
// a 64 x 64 grid), linearly interpolated.
float meanSchlickWeight(float cosO) {
  constexpr int kEntries = 33, kGrid = 64;
  static const std::array<float, kEntries> table = [] {
    std::array<float, kEntries> t{};
    for (int e = 0; e < kEntries; ++e) {
      const float mu = float(e) / float(kEntries - 1);
      const glm::vec3 wo(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, std::max(mu, 1e-4f));
      double sum = 0.0;
      for (int i = 0; i < kGrid; ++i) {
        const float c = std::sqrt((float(i) + 0.5f) / float(kGrid)), s = std::sqrt(1.0f - c * c);
        for (int j = 0; j < kGrid; ++j) {
          const float phi = 2.0f * kPi * (float(j) + 0.5f) / float(kGrid);
          const glm::vec3 wi(s * std::cos(phi), s * std::sin(phi), c);
          const float x = 1.0f - std::clamp(glm::dot(wo, glm::normalize(wo + wi)), 0.0f, 1.0f);
          sum += double(x * x * x * x * x);
        }
      }
      t[std::size_t(e)] = float(sum / double(kGrid * kGrid));
    }
    return t;
  }();
  const float x = std::clamp(cosO, 0.0f, 1.0f) * float(kEntries - 1);
  const int i = std::min(int(x), kEntries - 2);
  return table[std::size_t(i)] + (table[std::size_t(i) + 1] - table[std::size_t(i)]) * (x - float(i));
}

// The cosine-weighted mean over wi of diffuseFresnelScale: every channel's Schlick term is
// linear in the same weight, so the largest F0 stays the largest and the mean is exact.
float meanDiffuseFresnelScale(const ShadingMaterial& m, float cosO) {
  const float f0 = maxComponent(m.dielectricF0), w = meanSchlickWeight(cosO);
  return 1.0f - (f0 + (m.dielectricF90 - f0) * w);
}

glm::vec3 evalCoat(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  const glm::vec3& n = m.clearcoatNormal;
  const glm::vec3 h = glm::normalize(wo + wi);
  return glm::vec3(m.clearcoat * scene::coatLobe(m.clearcoatRoughness, glm::dot(n, h), glm::dot(n, wi), glm::dot(n, wo),
                                                 glm::dot(wo, h)));
}

// The sheen and clear-coat layers over a base reflection f_base(wo, wi): the base scaled by
// what the layers leave it, plus the layers' own lobes.
glm::vec3 overLayers(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi, glm::vec3 base) {
  if (m.hasSheen()) {
    const glm::vec3 h = glm::normalize(wo + wi);
    base = base * sheenScale(m, wo.z, wi.z) + m.sheenColor * scene::sheenLobe(m.sheenRoughness, h.z, wi.z, wo.z);
  }
  if (m.hasClearcoat()) base = base * (1.0f - coatWeight(m, wo)) + evalCoat(m, wo, wi);
  return base;
}

// Pdf of a GGX reflection about the coat normal.
float coatPdf(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  const glm::vec3 h = glm::normalize(wo + wi);
  const float oh = glm::dot(wo, h);
  const float nh = glm::dot(m.clearcoatNormal, h);
  if (oh <= 0.0f || nh <= 0.0f) return 0.0f;
  return ggxD(scene::coatAlpha(m.clearcoatRoughness), nh) * nh / (4.0f * oh);
}

// The base layer's pdf (diffuse cosine and GGX, by specularProbability).
float pdfBase(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  const float ps = specularProbability(m, wo.z);
  float pdf = (1.0f - ps) * wi.z * kInvPi;
  if (ps > 0.0f && !m.deltaSpecular()) pdf += ps * GlossyLobe(m).pdf(wo, wi);
  return pdf;
}

}  // namespace

float coatProbability(const ShadingMaterial& m, const glm::vec3& wo) { return std::min(coatWeight(m, wo), 0.9f); }

glm::vec3 evalOpaque(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  return overLayers(m, wo, wi, fresnelDiffuse(m, wo, wi) + evalGlossy(m, wo, wi));
}

float baseLayerWeight(const ShadingMaterial& m, const glm::vec3& wo) { return 1.0f - coatWeight(m, wo); }

float diffuseLayerScale(const ShadingMaterial& m, const glm::vec3& wo) {
  const float scale = baseLayerWeight(m, wo) * meanDiffuseFresnelScale(m, wo.z);
  if (!m.hasSheen()) return scale;
  // The cosine-weighted mean over wi of the sheen's scale: cos^2 theta_i uniform in [0, 1).
  constexpr int kSteps = 16;
  float mean = 0.0f;
  for (int i = 0; i < kSteps; ++i) mean += sheenScale(m, wo.z, std::sqrt((float(i) + 0.5f) / float(kSteps)));
  return scale * mean / float(kSteps);
}

bool hasNonLambertian(const ShadingMaterial& m) {
  return (m.hasSpecular() && !m.deltaSpecular()) || m.hasSheen() || m.hasClearcoat();
}

glm::vec3 evalNonLambertian(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  return overLayers(m, wo, wi, evalGlossy(m, wo, wi));
}

namespace {

// The lobes sampleNonLambertian draws from and their probabilities: the coat by its weight,
// the rough specular lobe, and the cosine hemisphere for sheen (alone, or a fifth beside the
// specular lobe, whose narrow peak would leave the broad sheen lobe undersampled).
struct NonLambertianLobes {
  float coat = 0.0f, glossy = 0.0f, cosine = 0.0f;
  NonLambertianLobes(const ShadingMaterial& m, const glm::vec3& wo) {
    const bool rough = m.hasSpecular() && !m.deltaSpecular();
    coat = m.hasClearcoat() ? coatProbability(m, wo) : 0.0f;
    const float rest = 1.0f - coat;
    glossy = rough ? rest * (m.hasSheen() ? 0.8f : 1.0f) : 0.0f;
    cosine = m.hasSheen() ? rest - glossy : 0.0f;
    const float total = coat + glossy + cosine;
    if (total > 0.0f) {
      coat /= total;
      glossy /= total;
      cosine /= total;
    }
  }
  float pdf(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) const {
    float p = cosine * wi.z * kInvPi;
    if (coat > 0.0f) p += coat * coatPdf(m, wo, wi);
    if (glossy > 0.0f) p += glossy * GlossyLobe(m).pdf(wo, wi);
    return p;
  }
};

}  // namespace

BsdfSample sampleNonLambertian(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v) {
  BsdfSample s;
  if (wo.z <= 0.0f || !hasNonLambertian(m)) return s;
  const NonLambertianLobes lobes(m, wo);
  if (lobe < lobes.coat) {
    const Frame coat(m.clearcoatNormal);
    s.wi = coat.toWorld(ggxReflection(scene::coatAlpha(m.clearcoatRoughness), coat.toLocal(wo), u, v));
  } else if (lobe < lobes.coat + lobes.glossy) {
    s.wi = GlossyLobe(m).reflect(wo, u, v);
  } else {
    s.wi = cosineHemisphere(u, v);
  }
  if (s.wi.z <= 0.0f) return s;
  s.pdf = lobes.pdf(m, wo, s.wi);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = evalNonLambertian(m, wo, s.wi) * (s.wi.z / s.pdf);
  s.valid = isFinite(s.weight);
  return s;
}

float pdfOpaque(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const float pc = coatProbability(m, wo);
  const float base = pdfBase(m, wo, wi);
  return pc > 0.0f ? pc * coatPdf(m, wo, wi) + (1.0f - pc) * base : base;
}

OpaqueLobe opaqueLobe(const ShadingMaterial& m, const glm::vec3& wo, float lobe) {
  const float pc = coatProbability(m, wo);
  if (lobe < pc) return OpaqueLobe::Coat;
  const float rest = pc > 0.0f ? std::min((lobe - pc) / (1.0f - pc), kOneMinusEpsilon) : lobe;
  return rest < specularProbability(m, wo.z) ? OpaqueLobe::Specular : OpaqueLobe::Diffuse;
}

BsdfSample sampleOpaque(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v) {
  BsdfSample s;
  if (wo.z <= 0.0f) return s;
  switch (opaqueLobe(m, wo, lobe)) {
    case OpaqueLobe::Coat: {
      // The coat's GGX lobe about its own normal.
      const Frame coat(m.clearcoatNormal);
      s.wi = coat.toWorld(ggxReflection(scene::coatAlpha(m.clearcoatRoughness), coat.toLocal(wo), u, v));
      break;
    }
    case OpaqueLobe::Specular:
      if (m.deltaSpecular()) {
        // Perfect mirror: f cos / pdf = F / (probability of this lobe), under the coat's share.
        const float pc = coatProbability(m, wo), ps = specularProbability(m, wo.z);
        s.wi = glm::vec3(-wo.x, -wo.y, wo.z);
        s.weight = m.specularFresnel(wo.z) * ((1.0f - coatWeight(m, wo)) / (ps * (1.0f - pc)));
        s.delta = true;
        s.valid = isFinite(s.weight);
        return s;
      }
      s.wi = GlossyLobe(m).reflect(wo, u, v);
      break;
    case OpaqueLobe::Diffuse: s.wi = cosineHemisphere(u, v); break;
  }
  if (s.wi.z <= 0.0f) return s;
  s.pdf = pdfOpaque(m, wo, s.wi);
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return s;
  s.weight = evalOpaque(m, wo, s.wi) * (s.wi.z / s.pdf);
  s.valid = isFinite(s.weight);
  return s;
}

PartSample sampleOpaquePart(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v) {
  PartSample out;
  BsdfSample& s = out.sample;
  if (wo.z <= 0.0f) return out;
  // Choice probabilities from each component's reflectance towards wo (luminance).
  const bool mirror = m.hasSpecular() && m.deltaSpecular();
  const float wMirror = mirror ? luminance(m.specularFresnel(wo.z)) * baseLayerWeight(m, wo) : 0.0f;
  const float wDiffuse = luminance(m.diffuseColor()) * diffuseLayerScale(m, wo);
  float wGlossy = 0.0f;
  if (hasNonLambertian(m)) {
    if (m.hasSpecular() && !m.deltaSpecular()) wGlossy += luminance(m.specularFresnel(wo.z));
    if (m.hasClearcoat()) wGlossy += coatWeight(m, wo);
    if (m.hasSheen()) wGlossy += maxComponent(m.sheenColor);
  }
  const float total = wMirror + wDiffuse + wGlossy;
  if (!(total > 0.0f)) return out;
  const float x = lobe * total;
  if (x < wDiffuse) {
    const float p = wDiffuse / total;
    s.wi = cosineHemisphere(u, v);
    if (s.wi.z <= 0.0f) return out;
    // f = diffuse / pi under the layers; pdf = cos / pi.
    s.pdf = p * s.wi.z * kInvPi;
    s.weight = layeredDiffuse(m, wo, s.wi) * (kPi / p);
    out.part = OpaquePart::Diffuse;
  } else if (x < wDiffuse + wGlossy) {
    s = sampleNonLambertian(m, wo, (x - wDiffuse) / wGlossy, u, v);
    const float p = wGlossy / total;
    s.weight /= p;
    s.pdf *= p;
    out.part = OpaquePart::Glossy;
  } else {
    const float p = wMirror / total;
    s.wi = glm::vec3(-wo.x, -wo.y, wo.z);
    s.weight = m.specularFresnel(wo.z) * (baseLayerWeight(m, wo) / p);
    s.delta = true;
    s.pdf = 0.0f;
    out.part = OpaquePart::Mirror;
  }
  s.valid = s.wi.z > 0.0f && isFinite(s.weight) && (s.delta || s.pdf > 0.0f);
  return out;
}

glm::vec3 sampleMicrofacetNormal(const ShadingMaterial& m, float u, float v) { return scene::ggxNormal(m.alpha, u, v); }

float microfacetWeight(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& h) {
  const float g = ggxG1(m.alpha, std::fabs(wo.z)) * ggxG1(m.alpha, std::fabs(wi.z));
  const float w = std::fabs(glm::dot(wo, h)) * g / (std::fabs(wo.z) * std::fabs(h.z));
  return std::isfinite(w) ? w : 0.0f;
}

}  // namespace pr::rt
