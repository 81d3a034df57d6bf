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

TEST_CASE("MaterialModel: the photon map's anisotropic highlight is the path tracer's GGX lobe, turned with the material") {
  // A rough anisotropic metal floor under a point light, seen from above: the highlight is
  // elongated along the anisotropy direction. Both passes of the photon map use the same
  // anisotropic GGX lobe as the path tracer, so the highlight's shape (the ratio of its second
  // moments along x and y) is the same, and turning the material by 90 degrees inverts it.
  auto shape = [](float rotation, bool photonmap) {
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
    io.spp = 16;
    rt::TraceJob job{s, cam, kN, kN, {}};
    pm::PhotonMapSettings settings;
    settings.globalPhotons = 2000;
    settings.causticPhotons = 0;
    settings.gatherRays = 16;
    if (photonmap) job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, kN, kN, io, settings);
    else job.options.integrator = io;
    par::Runtime runtime(2);
    const image::Image img = rt::renderRays(job, "image-space", runtime).image;
    double mx = 0.0, my = 0.0;
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) {
        const double l = img.pixels[size_t(y * kN + x)].x;
        mx += l * (x - kN / 2.0 + 0.5) * (x - kN / 2.0 + 0.5);
        my += l * (y - kN / 2.0 + 0.5) * (y - kN / 2.0 + 0.5);
      }
    return mx / my;
  };
  const double along = shape(0.0f, true), across = shape(3.14159265f / 2.0f, true);
  const double pathAlong = shape(0.0f, false), pathAcross = shape(3.14159265f / 2.0f, false);
  CAPTURE(along);
  CAPTURE(across);
  CAPTURE(pathAlong);
  CAPTURE(pathAcross);
  CHECK((along > 1.3 * across || across > 1.3 * along));  // elongated one way, then the other
  CHECK(along * across == doctest::Approx(1.0).epsilon(0.15));  // by symmetry, the same ratio turned
  CHECK(along == doctest::Approx(pathAlong).epsilon(0.05));
  CHECK(across == doctest::Approx(pathAcross).epsilon(0.05));
}
