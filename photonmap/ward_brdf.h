// The Ward anisotropic BRDF (Ward, "Measuring and Modeling Anisotropic Reflection", 1992), the
// photon-map integrator's glossy lobe for KHR_materials_anisotropy materials, with the
// half-vector sampling of Walter ("Notes on the Ward BRDF", 2005). Vectors in the lobe's own
// frame: z the shading normal, x the anisotropy direction (alphaX along it).
#pragma once

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/sampling.h"

namespace pr::pm {

struct WardLobe {
  glm::vec3 f0{0.04f};  // specular reflectance at normal incidence (Schlick's F at h . wo scales the lobe)
  float alphaX = 0.1f;  // rms slope along the anisotropy direction
  float alphaY = 0.1f;  // and across it
  float f90 = 1.0f;     // reflectance at grazing incidence (KHR_materials_specular)
};

// f(wo, wi) = F(h.wo) / (4 pi ax ay sqrt(cos_i cos_o)) exp(-tan^2(theta_h) (cos^2 phi_h / ax^2 + sin^2 phi_h / ay^2)),
// zero below the surface. Symmetric in wo and wi (reciprocal).
glm::vec3 evalWard(const WardLobe& lobe, const glm::vec3& wo, const glm::vec3& wi);
// wi from the half-vector distribution p(h) = exp(...) / (pi ax ay cos^3 theta_h) (normalised over
// the hemisphere), pdf(wi) = p(h) / (4 h.wo); weight = f cos_i / pdf = F (h.wo) cos^3(theta_h) sqrt(cos_i / cos_o).
rt::BsdfSample sampleWard(const WardLobe& lobe, const glm::vec3& wo, float u, float v);

// The lobe of an anisotropic material (m.anisotropy > 0) with glTF's mapping of strength to
// roughness along the direction: alpha_x = mix(alpha, 1, strength^2), alpha_y = alpha (the
// GGX alpha, at least 1e-3 so the lobe stays finite).
WardLobe wardLobe(const rt::ShadingMaterial& m);

}  // namespace pr::pm
