// Bsdf: the glTF material model of the integrators. Sampled weights equal f cos / pdf, f is
// reciprocal, a rough white dielectric reflects exactly its base colour (Lambertian), a
// glossy lobe never creates energy, Fresnel and Snell hold, total internal reflection is total.
#include <cmath>

#include <doctest/doctest.h>

#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/sampling.h"

using namespace pr;

namespace {

rt::ShadingMaterial material(float base, float metallic, float roughness) {
  rt::ShadingMaterial m;
  m.baseColor = glm::vec3(base);
  m.metallic = metallic;
  m.roughness = roughness;
  m.alpha = roughness * roughness;
  return m;
}

// Directional albedo: E[weight] over sampleOpaque, n samples (counter-based numbers).
double albedo(const rt::ShadingMaterial& m, const glm::vec3& wo, int n) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const rt::BsdfSample s = m.deltaSpecular() ? rt::BsdfSample{} : rt::sampleOpaque(m, wo, rt::sample1D(9, uint32_t(i), 0, 0, 0),
                                                                                       rt::sample1D(9, uint32_t(i), 0, 0, 1),
                                                                                       rt::sample1D(9, uint32_t(i), 0, 0, 2));
    if (s.valid) sum += s.weight.x;
  }
  return sum / n;
}

}  // namespace

TEST_CASE("Bsdf: sampled weight is f cos / pdf, and f is reciprocal") {
  const glm::vec3 wo = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
  for (float roughness : {0.3f, 0.7f}) {
    const rt::ShadingMaterial m = material(0.8f, 0.5f, roughness);
    for (uint32_t i = 0; i < 200; ++i) {
      const rt::BsdfSample s = rt::sampleOpaque(m, wo, rt::sample1D(4, i, 0, 0, 0), rt::sample1D(4, i, 0, 0, 1), rt::sample1D(4, i, 0, 0, 2));
      if (!s.valid) continue;
      const glm::vec3 f = rt::evalOpaque(m, wo, s.wi);
      CHECK(s.pdf == doctest::Approx(rt::pdfOpaque(m, wo, s.wi)).epsilon(1e-4));
      CHECK(s.weight.x == doctest::Approx(f.x * s.wi.z / s.pdf).epsilon(1e-3));
      CHECK(rt::evalOpaque(m, s.wi, wo).x == doctest::Approx(f.x).epsilon(1e-4));
    }
  }
}

TEST_CASE("Bsdf: a rough dielectric is Lambertian with albedo = base colour; glossy lobes do not create energy") {
  const glm::vec3 wo = glm::normalize(glm::vec3(0.5f, 0.0f, 0.7f));
  // Cosine sampling of a Lambertian lobe has weight = albedo exactly for every sample.
  CHECK(albedo(material(0.5f, 0.0f, 1.0f), wo, 1000) == doctest::Approx(0.5).epsilon(1e-5));
  // A white metal with a GGX lobe reflects at most everything: single scattering loses the
  // light that would scatter between microfacets, more as roughness grows. The lower bounds
  // are an independent Monte Carlo integration of the same model (separable Smith G):
  // 0.998, 0.899 and 0.447 for these roughnesses at this wo.
  const float roughness[] = {0.2f, 0.5f, 0.9f};
  const double expected[] = {0.998, 0.899, 0.447};
  for (int i = 0; i < 3; ++i) {
    CAPTURE(roughness[i]);
    const double a = albedo(material(1.0f, 1.0f, roughness[i]), wo, 20000);
    CHECK(a <= 1.02);  // 1 plus Monte Carlo error
    CHECK(a == doctest::Approx(expected[i]).epsilon(0.03));
  }
}

TEST_CASE("Bsdf: Fresnel and refraction handle total internal reflection") {
  // From glass (n = 1.5) to air the critical angle is asin(1/1.5) = 41.8 degrees.
  const float eta = 1.0f / 1.5f;
  const float beyond = std::cos(glm::radians(60.0f)), within = std::cos(glm::radians(30.0f));
  CHECK(rt::fresnelDielectric(beyond, eta) == 1.0f);
  glm::vec3 wt;
  const glm::vec3 n(0, 0, 1);
  CHECK_FALSE(rt::refractDirection(glm::vec3(std::sin(std::acos(beyond)), 0, beyond), n, eta, wt));
  REQUIRE(rt::refractDirection(glm::vec3(std::sin(std::acos(within)), 0, within), n, eta, wt));
  // Snell: n1 sin(theta1) = n2 sin(theta2), so sin(theta_t) = 1.5 sin(30) = 0.75 on the far side.
  CHECK(wt.z < 0.0f);
  CHECK(std::sqrt(wt.x * wt.x + wt.y * wt.y) == doctest::Approx(0.75).epsilon(1e-4));
  // Normal incidence from air into glass: ((1.5 - 1) / (1.5 + 1))^2 = 0.04.
  CHECK(rt::fresnelDielectric(1.0f, 1.5f) == doctest::Approx(0.04).epsilon(1e-4));
}
