// The glTF material at a hit as the integrators see it: resolved by the shared
// scene::resolveMaterial (textures, vertex colour, normal maps), and the BSDF it stands for - a
// Lambertian diffuse part, a GGX microfacet specular part whose roughness makes the glossy lobe
// (a mirror below kDeltaAlpha), a smooth dielectric part for transmission, and the sheen and
// clear-coat layers over the opaque part (common/scene/material_layers.h).
// Evaluated by the PE that shades the hit; shared by the Whitted and path-tracing integrators.
#pragma once

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "common/scene/surface_material.h"
#include "raytrace/core/interaction.h"

namespace pr::rt {

// GGX alpha (roughness^2) below which the specular lobe is treated as a perfect mirror: a
// lobe this narrow (under 2 degrees) cannot be sampled usefully by light sampling.
inline constexpr float kDeltaAlpha = 1.0e-3f;

// The material at one hit, textures applied. Vectors in the local shading frame (z = normal
// on the side of wo) are used by the BSDF functions below.
struct ShadingMaterial {
  glm::vec3 baseColor{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  float alpha = 1.0f;         // GGX alpha = roughness^2
  float transmission = 0.0f;  // weight of the smooth dielectric part
  float ior = 1.5f;
  glm::vec3 emission{0.0f};   // radiance (nits) leaving the emitting side
  bool doubleSided = false;
  // KHR_materials_anisotropy: strength in [0, 1] and the direction in the tangent plane, as
  // (cos, sin) of its angle from the uv tangent (rotation and texture applied), which
  // ShadingFrame makes the local x axis of the anisotropic GGX lobe.
  float anisotropy = 0.0f;
  glm::vec2 anisotropyDirection{1.0f, 0.0f};
  // KHR_materials_specular: the dielectric Fresnel's F0 and F90 (0.04 and 1 without it).
  glm::vec3 dielectricF0{0.04f};
  float dielectricF90 = 1.0f;
  // The shading normal with the normal map applied (world space, on the geometric front side).
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  // KHR_materials_sheen and KHR_materials_clearcoat layers.
  glm::vec3 sheenColor{0.0f};
  float sheenRoughness = 0.0f;
  float clearcoat = 0.0f;
  float clearcoatRoughness = 0.0f;
  glm::vec3 clearcoatNormalWorld{0.0f, 0.0f, 1.0f};
  glm::vec3 clearcoatNormal{0.0f, 0.0f, 1.0f};  // in the local shading frame (set by ShadingFrame)
  // KHR_materials_volume: a solid (thicknessFactor > 0) absorbs along the path inside it by
  // Beer-Lambert with this coefficient per unit length, -ln(attenuationColor) / distance.
  bool thinWalled = true;
  glm::vec3 attenuation{0.0f};

  // The opaque lobes below carry their own weights in the glTF spec's mix (Appendix B, with
  // KHR_materials_transmission's mix(diffuse_brdf, specular_btdf, transmission)): the diffuse
  // part holds (1 - metallic)(1 - transmission), the dielectric specular layer (1 - transmission)
  // - the transmissive share's reflection is the dielectric part's exact Fresnel term - and the
  // metal part metallic. Integrators use them as they are (never times another opaque weight);
  // one that picks the opaque part with probability 1 - dielectricWeight() divides by it.
  //
  // The Lambertian part: the non-metallic, non-transmissive share of baseColor.
  glm::vec3 diffuseColor() const { return (1.0f - metallic) * (1.0f - transmission) * baseColor; }
  // Specular reflectance at normal incidence: the dielectric's F0 (4% at ior 1.5, or
  // KHR_materials_specular's) on its opaque share, the base colour on the metal's. A surface
  // meant to be purely Lambertian says so with KHR_materials_specular's specularFactor 0.
  glm::vec3 specularF0() const { return glm::mix(dielectricF0 * (1.0f - transmission), baseColor, metallic); }
  // Reflectance at grazing incidence: 1 for metals, specularFactor for dielectrics.
  float specularF90() const { return dielectricF90 * (1.0f - transmission) * (1.0f - metallic) + metallic; }
  // No specular lobe at all when F0 and F90 are zero (specularFactor 0 on a non-metal, or
  // transmission 1): the opaque part is then exactly Lambertian.
  bool hasSpecular() const {
    const glm::vec3 f0 = specularF0();
    return f0.x > 0.0f || f0.y > 0.0f || f0.z > 0.0f || specularF90() > 0.0f;
  }
  // The specular lobe's Fresnel term at cosine cosTheta (Schlick from F0 to F90).
  glm::vec3 specularFresnel(float cosTheta) const;
  // What the dielectric's Fresnel layer leaves the diffuse part under it, for a pair of
  // directions whose half-vector h has cos(wo, h) = cosH: the spec's fresnel_mix,
  // 1 - max(F_dielectric(cosH)), which keeps a white diffuse surface under its layer from
  // reflecting more than it receives. 1 without the layer (specularFactor 0).
  float diffuseFresnelScale(float cosH) const;
  // The base-colour tint of a refraction through this interface: once per pass through a solid
  // (on entering it), at every crossing of a thin wall.
  glm::vec3 transmissionTint(bool frontFace) const { return thinWalled || frontFace ? baseColor : glm::vec3(1.0f); }
  // What a refraction does to the radiance an eye path carries back across this interface,
  // eta = n_t / n_i along the path: radiance is flux per solid angle and refraction squeezes
  // solid angle by eta^2, so light leaving glass into air loses it and light entering gains it
  // (Veach 1997, 5.2). On a path that enters a solid and leaves it the two cancel; light
  // reflected diffusely inside one keeps one. Photons carry flux, which crossing leaves as is.
  float refractedRadianceScale(bool frontFace) const {
    const float eta = frontFace ? ior : 1.0f / ior;
    return 1.0f / (eta * eta);
  }
  bool hasSheen() const { return sheenColor.x > 0.0f || sheenColor.y > 0.0f || sheenColor.z > 0.0f; }
  bool hasClearcoat() const { return clearcoat > 0.0f; }
  bool deltaSpecular() const { return alpha < kDeltaAlpha; }
  // Whether the opaque part has a lobe that is not a perfect mirror - diffuse, a rough
  // specular lobe, sheen or a clear coat (always sampled as a lobe): where photons are stored
  // and the photon maps' estimates are read.
  bool hasNonDeltaPart() const {
    const glm::vec3 d = diffuseColor();
    return d.x > 0.0f || d.y > 0.0f || d.z > 0.0f || (hasSpecular() && !deltaSpecular()) || hasSheen() || hasClearcoat();
  }
  // Share of the smooth dielectric (refracting) part, and the probability with which the
  // samplers pick it over the opaque lobes.
  float dielectricWeight() const { return transmission * (1.0f - metallic); }
  float opaqueProbability() const { return 1.0f - dielectricWeight(); }
};

// textures = false evaluates the material from its factors alone (the plan's textures off).
ShadingMaterial evalMaterial(const scene::Scene& scene, const SurfaceInteraction& si, bool textures = true);
using scene::usesTextures;

// Beer-Lambert transmittance of the path segment that ended at si from inside a solid of this
// material (the back of an absorbing volume): exp(-attenuation * distance), distance the
// segment's length; 1 anywhere else. Finite and flushed to 0 below 1e-30 (no denormal
// throughput), for any distance and attenuation, including an attenuationDistance of 1e-3.
glm::vec3 volumeTransmittance(const ShadingMaterial& m, const SurfaceInteraction& si, const Ray& ray);

// Radiance emitted towards wo: the material's emission on its front side (both sides when
// double-sided), zero otherwise.
glm::vec3 emittedRadiance(const ShadingMaterial& m, const SurfaceInteraction& si);

// Schlick's approximation of the conductor/dielectric Fresnel term (glTF 2.0 appendix B),
// rising from f0 at normal incidence to f90 at grazing.
glm::vec3 fresnelSchlick(const glm::vec3& f0, float cosTheta, float f90 = 1.0f);
// Exact unpolarised Fresnel reflectance of a smooth dielectric interface; eta = n_t / n_i,
// cosI > 0 on the incident side. Returns 1 for total internal reflection.
float fresnelDielectric(float cosI, float eta);
// Refracts unit w (pointing away from the surface, on n's side) through the interface with
// relative ior eta = n_t / n_i; false on total internal reflection.
bool refractDirection(const glm::vec3& w, const glm::vec3& n, float eta, glm::vec3& wt);

// The opaque (diffuse + glossy) part in the local frame, wo.z > 0: f(wo, wi) (without cos),
// and the pdf of sampleOpaque for wi. Both zero when wi is below the surface.
glm::vec3 evalOpaque(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi);
float pdfOpaque(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi);
// Samples wi for the opaque part with (lobe, u, v) in [0,1)^3: the specular lobe with
// probability specularProbability, else the cosine hemisphere. weight = f cos / pdf. For a
// delta specular lobe the mirror direction is returned with delta = true and pdf = 0.
struct BsdfSample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};
  float pdf = 0.0f;
  bool delta = false;
  bool valid = false;
};
BsdfSample sampleOpaque(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v);
// The lobe sampleOpaque takes for `lobe`: the clear coat below coatProbability, then (lobe
// rescaled to the rest) the specular lobe below specularProbability, else the diffuse one.
// Integrators that skip a lobe's rays under the plan ask it before sampling.
enum class OpaqueLobe { Coat, Specular, Diffuse };
OpaqueLobe opaqueLobe(const ShadingMaterial& m, const glm::vec3& wo, float lobe);
// The dielectric part with roughness (Walter et al. 2007): a GGX microfacet normal for (u, v)
// in the local frame (z = normal), and the weight of reflecting or refracting wo about it when
// the choice between the two is made with probability F: |wo.h| G(wo, wi) / (|wo.n| |h.n|).
glm::vec3 sampleMicrofacetNormal(const ShadingMaterial& m, float u, float v);
float microfacetWeight(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& h);
// The rough specular (GGX) lobe alone, for integrators that treat it apart from the diffuse
// part (the photon map: glossy reflection by Monte Carlo, diffuse by density estimation):
// f_s(wo, wi) without cos (zero without a rough specular lobe), and a sample of wi from the
// GGX half-vector distribution with weight = f_s cos / pdf and its pdf.
glm::vec3 evalGlossy(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi);
BsdfSample sampleGlossy(const ShadingMaterial& m, const glm::vec3& wo, float u, float v);
// The opaque part's lobes other than its Lambertian base - the rough specular lobe under the
// layers, sheen and clear coat (evalOpaque less the layered diffuse term): what the photon
// map's glossy rays carry at an eye point, where the base's light comes from the maps. Sampled
// from the coat and specular lobes by their weights and the cosine hemisphere for sheen;
// weight = f cos / pdf. hasNonLambertian: whether there is any such lobe.
bool hasNonLambertian(const ShadingMaterial& m);
glm::vec3 evalNonLambertian(const ShadingMaterial& m, const glm::vec3& wo, const glm::vec3& wi);
BsdfSample sampleNonLambertian(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v);
// The opaque part sampled one component at a time, each weighted by its own BRDF alone
// (weight = f_part cos / (P(part) pdf_part)), so the component a sample came from is the kind of
// reflection it stands for: the layered Lambertian base, the non-Lambertian lobes above, or an
// ideal mirror base (delta). The components' weights sum to the opaque BSDF's in expectation.
// What photon tracing uses, whose paths are sorted by the kinds of reflection they took.
enum class OpaquePart { Diffuse, Glossy, Mirror };
struct PartSample {
  BsdfSample sample;
  OpaquePart part = OpaquePart::Diffuse;
};
PartSample sampleOpaquePart(const ShadingMaterial& m, const glm::vec3& wo, float lobe, float u, float v);
// What the clear coat leaves the layers under it towards wo (1 - its Fresnel weight).
float baseLayerWeight(const ShadingMaterial& m, const glm::vec3& wo);
// The share of the diffuse base left under the dielectric's Fresnel layer, the sheen and the
// clear coat towards wo for light arriving alike from every direction (the Fresnel and sheen
// losses depend on wi too; this is the product of their cosine-weighted means): what turns
// irradiance known without directions (an irradiance-cache record) into the layered diffuse
// radiance diffuseColor() / pi * E * scale. 1 without layers.
float diffuseLayerScale(const ShadingMaterial& m, const glm::vec3& wo);
// Probability that sampleOpaque picks the specular lobe (from Fresnel and diffuse luminance).
float specularProbability(const ShadingMaterial& m, float cosO);
// Probability that sampleOpaque picks the clear-coat lobe (its Fresnel weight towards wo).
float coatProbability(const ShadingMaterial& m, const glm::vec3& wo);

}  // namespace pr::rt
