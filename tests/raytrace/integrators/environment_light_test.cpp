// The environment light in the ray tracers: the white furnace - a convex diffuse sphere of
// albedo rho under a uniform environment of radiance L reflects exactly rho L at every point,
// for the path tracer (MIS of light and BSDF samples) and Whitted (light samples alone) - the
// background shows the environment, and every tracer gives the same image.
#include <doctest/doctest.h>

#include <memory>

#include "common/parallel/runtime.h"
#include "common/scene/effect_analysis.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"

using namespace pr;

namespace {

constexpr int kN = 24;

scene::Scene furnace(float albedo, float radiance) {
  scene::Scene s;
  test::addSphere(s, glm::vec3(0.0f, 0.0f, -3.0f), 1.0f, 24, test::addMaterial(s, test::diffuse(albedo)));
  s.environment = std::make_shared<const scene::Environment>(scene::Environment::uniform(glm::vec3(radiance), "test"));
  return s;
}

image::Image render(const scene::Scene& s, rt::IntegratorKind kind, const std::string& partition, int pes, int spp,
                    scene::EffectSet effects = scene::EffectSet::all()) {
  rt::TraceOptions o;
  o.integrator.effects = effects;
  o.integrator.kind = kind;
  o.integrator.spp = spp;
  o.integrator.maxDepth = 8;
  o.tileSizePx = 8;
  par::Runtime runtime(pes);
  return rt::renderRays(s, test::perspectiveAt(glm::vec3(0.0f), 0.6f), kN, kN, o, partition, runtime).image;
}

}  // namespace

TEST_CASE("EnvironmentLight: the white furnace reflects rho L, background L, for path tracing and Whitted") {
  const float rho = 0.6f, l = 2.0f;
  const scene::Scene s = furnace(rho, l);
  for (rt::IntegratorKind kind : {rt::IntegratorKind::Path, rt::IntegratorKind::Whitted}) {
    CAPTURE(rt::toString(kind));
    // 256 samples over 144 pixels: one uniform light sample each has a relative deviation of
    // about 1 (half the sphere is below the surface), so the mean is within 0.3 % (1 sigma).
    const image::Image img = render(s, kind, "sequential", 1, 256);
    // The sphere covers the centre; the corners see the environment.
    double sum = 0.0;
    int n = 0;
    for (int y = kN / 2 - 6; y < kN / 2 + 6; ++y)
      for (int x = kN / 2 - 6; x < kN / 2 + 6; ++x) {
        sum += img.pixels[size_t(y * kN + x)].x;
        ++n;
      }
    CHECK(sum / n == doctest::Approx(rho * l).epsilon(0.01));
    CHECK(img.pixels[0].x == doctest::Approx(l));
  }
}

TEST_CASE("EnvironmentLight: the furnace stays rho L when the plan turns indirect light off") {
  // A convex sphere receives no light from another surface, so the analysis turns indirect
  // (and glossy) continuations off; the environment's direct light must then come from light
  // sampling in full, not from an MIS share whose BSDF half is never traced.
  const float rho = 0.6f, l = 2.0f;
  const scene::Scene s = furnace(rho, l);
  const scene::Camera camera = test::perspectiveAt(glm::vec3(0.0f), 0.6f);
  const scene::RenderPlan plan = scene::analyzeEffects(s, &camera);
  REQUIRE_FALSE(plan.enabled().has(scene::Effect::IndirectDiffuse));
  const image::Image img = render(s, rt::IntegratorKind::Path, "sequential", 1, 256, plan.enabled());
  double sum = 0.0;
  int n = 0;
  for (int y = kN / 2 - 6; y < kN / 2 + 6; ++y)
    for (int x = kN / 2 - 6; x < kN / 2 + 6; ++x, ++n) sum += img.pixels[size_t(y * kN + x)].x;
  CHECK(sum / n == doctest::Approx(rho * l).epsilon(0.01));
}

TEST_CASE("EnvironmentLight: every tracer gives the same image under an environment") {
  const scene::Scene s = furnace(0.5f, 1.0f);
  const image::Image reference = render(s, rt::IntegratorKind::Path, "sequential", 1, 4);
  for (const char* partition : {"image-space", "image-space-cached", "object-space", "object"}) {
    CAPTURE(partition);
    CHECK(render(s, rt::IntegratorKind::Path, partition, 3, 4).pixels == reference.pixels);
  }
}
