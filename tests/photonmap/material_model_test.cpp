// One material model for every integrator: the glTF spec's weights (Appendix B, with
// KHR_materials_transmission's mix(diffuse, specular_btdf, transmission)) reach the image the
// same way through Whitted, the path tracer and the photon map. Comparing the integrators with
// each other cannot find a weight they all share, so each is checked against the spec's value.
#include <doctest/doctest.h>

#include <memory>
#include <string>

#include "common/parallel/runtime.h"
#include "photonmap/photon_map_integrator.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"

using namespace pr;

namespace {

constexpr int kSize = 8;

image::Image renderWith(const scene::Scene& s, const scene::Camera& cam, const std::string& integrator) {
  rt::IntegratorOptions io;
  io.spp = 4;
  io.maxDepth = 6;
  rt::TraceJob job{s, cam, kSize, kSize, {}};
  if (integrator == "photonmap") {
    pm::PhotonMapSettings settings;
    settings.globalPhotons = 4000;
    settings.causticPhotons = 4000;
    settings.photonBatch = 1000;
    settings.gatherRays = 32;
    job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, kSize, kSize, io, settings);
  } else {
    io.kind = integrator == "whitted" ? rt::IntegratorKind::Whitted : rt::IntegratorKind::Path;
    job.options.integrator = io;
  }
  job.options.tileSizePx = 4;
  par::Runtime runtime(2);
  return rt::renderRays(job, "image-space", runtime).image;
}

}  // namespace

TEST_CASE("MaterialModel: transmission 0.9 with specularFactor 0 reflects 0.1 of the base colour diffusely, in every integrator") {
  // A plane of that material under a directional light straight above, seen from above with no
  // environment: its refraction and its dielectric reflection leave into darkness, so each
  // pixel is the diffuse part alone, (1 - transmission) baseColor / pi * E. Next-event
  // estimation of a punctual light is exact in every integrator, and nothing else is lit
  // (a single plane: no indirect light, no caustic), so the tolerance is float rounding.
  const glm::vec3 base(0.8f, 0.6f, 0.4f);
  scene::Scene s;
  scene::Material m = test::diffuse(1.0f);
  m.baseColorFactor = glm::vec4(base, 1.0f);
  m.transmissionFactor = 0.9f;
  test::addGround(s, 2.0f, test::addMaterial(s, m));
  scene::PunctualLight sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  sun.intensity = 2.0f;
  s.lights.push_back(sun);
  const scene::Camera cam = test::topDownOrtho(3.0f, 1.0f);
  const glm::vec3 expected = 0.1f * base * (2.0f / 3.14159265f);
  for (const char* integrator : {"whitted", "path", "photonmap"}) {
    CAPTURE(integrator);
    const image::Image img = renderWith(s, cam, integrator);
    for (const glm::vec3& p : img.pixels)
      for (int c = 0; c < 3; ++c) REQUIRE(p[c] == doctest::Approx(expected[c]).epsilon(1.0e-4));
  }
}
