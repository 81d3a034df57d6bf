// The integrators skip the work of the RenderPlan's effects that are off, count it, and leave
// the image bit for bit the same when the analysis turned the effect off (it cannot appear):
// the skips never change the random numbers of what stays on, since each is a function of
// (seed, pixel, sample, depth, dim). Forcing an effect off that does appear changes the image
// and counts the skipped work; forcing on one that cannot appear changes nothing.
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;
using scene::Effect;

namespace {

constexpr int kSize = 32;

rt::TraceResult render(const scene::Scene& s, const scene::Camera& cam, rt::IntegratorKind kind, scene::EffectSet effects,
                       const std::string& partition = "sequential", int pes = 1) {
  rt::TraceOptions opt;
  opt.integrator.kind = kind;
  opt.integrator.spp = 2;
  opt.integrator.maxDepth = 6;
  opt.integrator.seed = 7;
  opt.integrator.effects = effects;
  opt.tileSizePx = 8;
  par::Runtime runtime(pes);
  return rt::renderRays(s, cam, kSize, kSize, opt, partition, runtime);
}

scene::EffectSet forced(const scene::RenderPlan& plan, const char* overrides) {
  return scene::applyOverrides(plan, scene::parseEffectOverrides(overrides)).enabled();
}

struct Bundled {
  scene::Scene scene;
  scene::Camera camera;
  scene::RenderPlan plan;
};

Bundled bundled(const char* file) {
  Bundled b{scene::loadGltf(test::sourceDir() / "scenes" / file), {}, {}};
  b.camera = scene::selectCamera(b.scene, "", 1.0f);
  b.plan = scene::analyzeEffects(b.scene, &b.camera);
  return b;
}

}  // namespace

TEST_CASE("EffectSkip: each bundled scene's analysed plan renders the all-on image bit for bit") {
  for (const char* file : {"cornell.gltf", "cornell-diffuse.gltf", "hotspot.gltf"}) {
    const Bundled b = bundled(file);
    for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
      CAPTURE(file);
      CAPTURE(rt::toString(kind));
      const rt::TraceResult all = render(b.scene, b.camera, kind, scene::EffectSet::all());
      const rt::TraceResult planned = render(b.scene, b.camera, kind, b.plan.enabled());
      CHECK(planned.image.pixels == all.image.pixels);
      CHECK(planned.rays.total() == all.rays.total());
    }
  }
}

TEST_CASE("EffectSkip: one convex sphere under a light skips shadow tests and bounces, image unchanged") {
  scene::Scene s;
  test::addSphere(s, {0, 0, 0}, 1.0f, 24, test::addMaterial(s, test::diffuse(0.7f)));
  scene::PunctualLight light;
  light.position = {1, 3, 2};
  light.intensity = 10.0f;
  s.lights.push_back(light);
  const scene::Camera cam = test::perspectiveAt({0, 0, 4}, 0.9f);
  const scene::RenderPlan plan = scene::analyzeEffects(s, &cam);
  REQUIRE_FALSE(plan.on(Effect::Shadows));
  REQUIRE_FALSE(plan.on(Effect::IndirectDiffuse));
  for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
    CAPTURE(rt::toString(kind));
    const rt::TraceResult all = render(s, cam, kind, scene::EffectSet::all());
    const rt::TraceResult planned = render(s, cam, kind, plan.enabled());
    CHECK(planned.image.pixels == all.image.pixels);
    CHECK(planned.rays.shadowRays == 0);
    CHECK(planned.rays.shadowTestsSkipped == all.rays.shadowRays);
    if (kind == rt::IntegratorKind::Path) {
      // Every bounce the all-on render traced left the sphere and found nothing.
      CHECK(planned.rays.indirectRaysSkipped == all.rays.continuationRays);
      CHECK(planned.rays.continuationRays == 0);
    }
  }
}

TEST_CASE("EffectSkip: mirrors under the environment keep their reflections under the analysed plan") {
  for (const test::ViewedScene& v : test::mirrorsUnderEnvironment()) {
    CAPTURE(v.name);
    const scene::RenderPlan plan = scene::analyzeEffects(v.scene, &v.camera);
    // Nothing can see anything else, but every reflection ray sees the environment.
    CHECK(plan.on(Effect::IdealSpecular));
    for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
      CAPTURE(rt::toString(kind));
      const rt::TraceResult all = render(v.scene, v.camera, kind, scene::EffectSet::all());
      const rt::TraceResult planned = render(v.scene, v.camera, kind, plan.enabled());
      CHECK(planned.image.pixels == all.image.pixels);
      CHECK(planned.rays.specularRaysSkipped == 0);
    }
  }
}

TEST_CASE("EffectSkip: forcing on effects that cannot appear leaves the image the same") {
  const Bundled b = bundled("cornell-diffuse.gltf");
  const scene::EffectSet on = forced(b.plan, "caustics=on,specular=on,glossy=on,transmission=on");
  CHECK(on != b.plan.enabled());
  const rt::TraceResult analysed = render(b.scene, b.camera, rt::IntegratorKind::Path, b.plan.enabled());
  const rt::TraceResult forcedOn = render(b.scene, b.camera, rt::IntegratorKind::Path, on);
  CHECK(forcedOn.image.pixels == analysed.image.pixels);
}

TEST_CASE("EffectSkip: forcing off effects that appear skips their work, counted, and changes the image") {
  const Bundled b = bundled("cornell.gltf");
  const rt::TraceResult all = render(b.scene, b.camera, rt::IntegratorKind::Path, b.plan.enabled());
  struct Case {
    const char* overrides;
    uint64_t rt::TraceStats::*counter;
  };
  for (const Case& c : {Case{"direct=off", &rt::TraceStats::lightSamplesSkipped},
                        Case{"emission=off", &rt::TraceStats::emissionSkipped},
                        Case{"shadows=off", &rt::TraceStats::shadowTestsSkipped},
                        Case{"specular=off", &rt::TraceStats::specularRaysSkipped},
                        Case{"transmission=off", &rt::TraceStats::transmissionRaysSkipped},
                        Case{"caustics=off", &rt::TraceStats::causticRaysSkipped},
                        Case{"indirect=off", &rt::TraceStats::indirectRaysSkipped}}) {
    CAPTURE(c.overrides);
    const rt::TraceResult off = render(b.scene, b.camera, rt::IntegratorKind::Path, forced(b.plan, c.overrides));
    CHECK(off.rays.*c.counter > 0);
    CHECK(all.rays.*c.counter == 0);
    CHECK(off.image.pixels != all.image.pixels);
  }
  // Whitted follows mirrors and refraction only.
  const rt::TraceResult whitted =
      render(b.scene, b.camera, rt::IntegratorKind::Whitted, forced(b.plan, "specular=off,transmission=off"));
  CHECK(whitted.rays.specularRaysSkipped > 0);
  CHECK(whitted.rays.transmissionRaysSkipped > 0);
  CHECK(whitted.rays.continuationRays == 0);
}

TEST_CASE("EffectSkip: skipped work is the same for every partition and P") {
  const Bundled b = bundled("cornell.gltf");
  const scene::EffectSet effects = forced(b.plan, "shadows=off,caustics=off");
  const rt::TraceResult reference = render(b.scene, b.camera, rt::IntegratorKind::Path, effects);
  for (const char* partition : {"image-space", "image-space-cached", "object-space", "object"}) {
    CAPTURE(partition);
    const rt::TraceResult r = render(b.scene, b.camera, rt::IntegratorKind::Path, effects, partition, 3);
    CHECK(r.image.pixels == reference.image.pixels);
    CHECK(r.rays.shadowTestsSkipped == reference.rays.shadowTestsSkipped);
    CHECK(r.rays.causticRaysSkipped == reference.rays.causticRaysSkipped);
  }
}
