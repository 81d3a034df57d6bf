// Path tracer: the white furnace converges to its analytic radiance; nested glass and total
// internal reflection give finite pixels and honour --max-depth.
#include <cmath>

#include <doctest/doctest.h>

#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"

using namespace pr;

namespace {

rt::TraceResult render(const scene::Scene& s, const scene::Camera& c, int w, int h, rt::IntegratorKind kind, int spp,
                       int maxDepth) {
  rt::TraceOptions opt;
  opt.integrator.kind = kind;
  opt.integrator.spp = spp;
  opt.integrator.maxDepth = maxDepth;
  par::Runtime runtime(1);
  return rt::renderRays(s, c, w, h, opt, "sequential", runtime);
}

bool allFinite(const image::Image& img) {
  for (const glm::vec3& p : img.pixels)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || p.x < 0 || p.y < 0 || p.z < 0) return false;
  return true;
}

}  // namespace

TEST_CASE("PathTracer: white furnace converges to E / (1 - albedo)") {
  // Inside a closed surface that emits E and reflects diffusely with albedo a everywhere, the
  // radiance is the same in every direction and satisfies L = E + a L, so L = E / (1 - a):
  // with E = 1 and a = 0.5, L = 2. Paths reach depth 64 with weight 0.5^64 at most, so the
  // truncation is negligible. 16x16 pixels x 64 samples = 16384 paths; the relative standard
  // error of the image mean measured over seeds is about 0.2%, so 1% is a 5-sigma bound.
  scene::Scene s;
  scene::Material m = test::diffuse(0.5f);
  m.emissiveFactor = glm::vec3(1.0f);
  m.doubleSided = true;
  const uint32_t mat = test::addMaterial(s, m);
  test::addSphere(s, glm::vec3(0.0f), 1.0f, 16, mat);
  test::addAreaLights(s, mat);
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.1f, -0.2f, 0.05f), 1.2f);
  const rt::TraceResult r = render(s, cam, 16, 16, rt::IntegratorKind::Path, 64, 64);
  REQUIRE(allFinite(r.image));
  double mean = 0.0;
  for (const glm::vec3& p : r.image.pixels) mean += (p.x + p.y + p.z) / 3.0;
  mean /= double(r.image.size());
  CHECK(mean == doctest::Approx(2.0).epsilon(0.01));
}

TEST_CASE("PathTracer: nested glass and total internal reflection stay finite and bounded") {
  // A glass ball (ior 1.5) holding a water ball (ior 1.33) over a lit floor, seen from above:
  // rays refract in and out, reflect totally inside, and bounce until --max-depth.
  scene::Scene s;
  const uint32_t floor = test::addMaterial(s, test::diffuse(0.8f));
  scene::Material glass;
  glass.roughnessFactor = 0.0f;
  glass.metallicFactor = 0.0f;
  glass.transmissionFactor = 1.0f;
  glass.ior = 1.5f;
  const uint32_t outer = test::addMaterial(s, glass);
  glass.ior = 1.33f;
  const uint32_t inner = test::addMaterial(s, glass);
  scene::Material lamp = test::diffuse(0.0f);
  lamp.emissiveFactor = glm::vec3(5.0f);
  lamp.doubleSided = true;
  const uint32_t light = test::addMaterial(s, lamp);
  test::addGround(s, 4.0f, floor);
  test::addSphere(s, glm::vec3(0.0f, 1.0f, 0.0f), 1.0f, 24, outer);
  test::addSphere(s, glm::vec3(0.0f, 1.0f, 0.0f), 0.5f, 16, inner);
  test::addTri(s, {-0.5f, 4.0f, -0.5f}, {0.5f, 4.0f, 0.5f}, {-0.5f, 4.0f, 0.5f}, light);
  test::addAreaLights(s, light);
  scene::PunctualLight point;
  point.position = glm::vec3(2.0f, 3.0f, 1.0f);
  point.intensity = 5.0f;
  s.lights.push_back(point);
  const scene::Camera cam = test::topDownOrtho(6.0f, 1.5f);
  for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
    CAPTURE(rt::toString(kind));
    for (int depth : {1, 3, 12}) {
      const rt::TraceResult r = render(s, cam, 16, 16, kind, 2, depth);
      CHECK(allFinite(r.image));
      // Whitted splits at each dielectric hit (at most 2 rays), the path tracer never:
      // the number of continuation rays is bounded by the depth limit.
      const uint64_t perCamera = kind == rt::IntegratorKind::Path ? uint64_t(depth) : (uint64_t(2) << depth);
      CHECK(r.rays.continuationRays <= r.rays.cameraRays * perCamera);
    }
  }
}
