// Tests of the Ward anisotropic BRDF (photonmap/ward_brdf.h): reciprocity; the sampling weights'
// mean equals the directional albedo integrated by quadrature; the lobe is wider along the
// anisotropy direction; and in the photon-map integrator, turning a material's anisotropy by 90
// degrees turns the highlight of a point light with it, as it does the path tracer's GGX lobe.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>

#include "common/parallel/runtime.h"
#include "photonmap/photon_map_integrator.h"
#include "photonmap/ward_brdf.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"

using namespace pr;

namespace {

constexpr float kPi = 3.14159265358979323846f;

glm::vec3 direction(float theta, float phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// int f(wo, wi) cos(theta_i) dwi over the hemisphere by the midpoint rule in (cos theta, phi).
double albedoByQuadrature(const pm::WardLobe& lobe, const glm::vec3& wo) {
  const int nc = 800, np = 800;
  double sum = 0.0;
  for (int i = 0; i < nc; ++i) {
    const float c = (float(i) + 0.5f) / float(nc);
    const float theta = std::acos(c);
    for (int j = 0; j < np; ++j) {
      const float phi = 2.0f * kPi * (float(j) + 0.5f) / float(np);
      sum += double(pm::evalWard(lobe, wo, direction(theta, phi)).x) * double(c);
    }
  }
  return sum * (1.0 / nc) * (2.0 * kPi / np);
}

}  // namespace

TEST_CASE("WardBrdf: reciprocal, and zero below the surface") {
  const pm::WardLobe lobe{glm::vec3(0.9f), 0.15f, 0.4f};
  for (float t1 : {0.1f, 0.6f, 1.2f})
    for (float t2 : {0.3f, 0.9f, 1.4f}) {
      const glm::vec3 a = direction(t1, 0.3f), b = direction(t2, 2.1f);
      const glm::vec3 fab = pm::evalWard(lobe, a, b), fba = pm::evalWard(lobe, b, a);
      CHECK(fab.x == doctest::Approx(fba.x).epsilon(1e-5));
    }
  CHECK(pm::evalWard(lobe, direction(0.5f, 0.0f), glm::vec3(0.0f, 0.3f, -0.9f)) == glm::vec3(0.0f));
}

TEST_CASE("WardBrdf: the mean sampling weight is the albedo integrated by quadrature") {
  const pm::WardLobe lobe{glm::vec3(1.0f), 0.1f, 0.35f};
  for (float theta : {0.0f, 0.5f, 1.0f}) {
    const glm::vec3 wo = direction(theta, 0.7f);
    const int n = 512;  // n x n stratified samples
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const rt::BsdfSample s = pm::sampleWard(lobe, wo, (float(i) + 0.5f) / float(n), (float(j) + 0.5f) / float(n));
        if (s.valid) sum += s.weight.x;
      }
    const double sampled = sum / double(n) / double(n);
    const double integrated = albedoByQuadrature(lobe, wo);
    CAPTURE(theta);
    CHECK(sampled == doctest::Approx(integrated).epsilon(0.02));
  }
}

TEST_CASE("WardBrdf: the lobe is wider along the anisotropy direction") {
  const pm::WardLobe lobe{glm::vec3(1.0f), 0.4f, 0.1f};
  double ax = 0.0, ay = 0.0;
  const int n = 128;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const rt::BsdfSample s = pm::sampleWard(lobe, glm::vec3(0, 0, 1), (float(i) + 0.5f) / n, (float(j) + 0.5f) / n);
      if (!s.valid) continue;
      ax += std::fabs(s.wi.x);
      ay += std::fabs(s.wi.y);
    }
  CHECK(ax > 2.5 * ay);
}

TEST_CASE("WardBrdf: turning the anisotropy by 90 degrees turns the photon map's highlight") {
  auto render = [](float rotation, bool photonmap) {
    scene::Scene s;
    scene::Material metal;
    metal.baseColorFactor = glm::vec4(0.9f, 0.9f, 0.9f, 1.0f);
    metal.metallicFactor = 1.0f;
    metal.roughnessFactor = 0.3f;
    metal.anisotropyStrength = 0.9f;
    metal.anisotropyRotation = rotation;
    test::addGround(s, 2.0f, test::addMaterial(s, metal));
    for (size_t v = 0; v < s.positions.size(); ++v) s.uvs[v] = glm::vec2(s.positions[v].x, s.positions[v].z);
    scene::PunctualLight light;
    light.position = glm::vec3(0.0f, 1.0f, 0.0f);
    light.intensity = 4.0f;
    s.lights.push_back(light);
    const scene::Camera cam = test::topDownOrtho(3.0f, 1.5f);
    constexpr int kN = 48;
    rt::IntegratorOptions io;
    io.spp = 4;
    rt::TraceJob job{s, cam, kN, kN, {}};
    pm::PhotonMapSettings settings;
    settings.globalPhotons = 2000;
    settings.causticPhotons = 0;
    settings.gatherRays = 16;
    if (photonmap) job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, kN, kN, io, settings);
    else job.options.integrator = io;
    par::Runtime runtime(2);
    const image::Image img = rt::renderRays(job, "image-space", runtime).image;
    // Second moments of the highlight along the image's x and y.
    double sum = 0.0, mx = 0.0, my = 0.0;
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) {
        const double l = img.pixels[size_t(y * kN + x)].x;
        sum += l;
        mx += l * (x - kN / 2.0 + 0.5) * (x - kN / 2.0 + 0.5);
        my += l * (y - kN / 2.0 + 0.5) * (y - kN / 2.0 + 0.5);
      }
    return mx / my;
  };
  const double along = render(0.0f, true), across = render(kPi / 2.0f, true);
  CAPTURE(along);
  CAPTURE(across);
  CHECK((along > 1.3 * across || across > 1.3 * along));  // elongated one way, then the other
  CHECK(along * across == doctest::Approx(1.0).epsilon(0.15));  // by symmetry, the same ratio turned
  // The path tracer's anisotropic GGX lobe elongates the highlight the same way, and turns it.
  const double pathAlong = render(0.0f, false), pathAcross = render(kPi / 2.0f, false);
  CAPTURE(pathAlong);
  CAPTURE(pathAcross);
  CHECK((pathAlong > 1.0) == (along > 1.0));
  CHECK((pathAlong > 1.3 * pathAcross || pathAcross > 1.3 * pathAlong));
  CHECK(pathAlong * pathAcross == doctest::Approx(1.0).epsilon(0.15));
}
