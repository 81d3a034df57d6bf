// The rasterizer applying the RenderPlan (SortOptions::effects): with textures off a textured
// model renders exactly as the same model with its texture references removed, with emission
// off an emitter renders as with its emission zeroed, with direct light off only emission is
// left; every sort point gives the sequential pipeline's image, and the skipped work is in the
// run record as the ray tracers name it (Plan/...).
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_point.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "run_record_support.h"
#include "test_support.h"

namespace pr::raster {
namespace {

constexpr int kW = 48, kH = 36;

scene::EffectSet without(scene::Effect e) {
  scene::EffectSet s = scene::EffectSet::all();
  s.set(e, false);
  return s;
}

std::vector<glm::vec3> sequential(const scene::Scene& s, const scene::Camera& cam, scene::EffectSet effects) {
  SequentialOptions o;
  o.effects = effects;
  const RegionFramebuffer fb = renderSequential(s, makeFrameView(cam, kW, kH), o);
  return toImage(fb).pixels;
}

// Every sort point at P = 3 with `effects` gives `expected`, and books `counterName` > 0.
void checkSortPoints(const scene::Scene& s, const scene::Camera& cam, scene::EffectSet effects,
                     const std::vector<glm::vec3>& expected, const std::string& counterName) {
  for (const SortPointInfo& info : sortPoints()) {  // the sequential-raster reference included
    CAPTURE(info.name);
    par::Runtime rt(3);
    SortOptions options;
    options.effects = effects;
    std::unique_ptr<SortPoint> sp = info.make();
    const RegionFramebuffer fb = renderFrame(*sp, s, makeFrameView(cam, kW, kH), options, rt);
    CHECK(toImage(fb).pixels == expected);
    CHECK(test::counterTotal(rt.record(), counterName) > 0);
  }
}

}  // namespace

TEST_CASE("RasterPlan: textures off renders the model with its textures removed, in every sort point") {
  if (!test::haveSharedScenes()) return;
  const scene::Scene textured = scene::loadGltf(test::sharedScenes() / "BoxTextured" / "glTF" / "BoxTextured.gltf");
  const scene::Camera cam = scene::selectCamera(textured, "auto", float(kW) / float(kH));
  scene::Scene plain = textured;
  for (scene::Material& m : plain.materials) {
    m.baseColorTexture = {};
    m.metallicRoughnessTexture = {};
    m.emissiveTexture = {};
  }
  const std::vector<glm::vec3> expected = sequential(plain, cam, scene::EffectSet::all());
  CHECK(sequential(textured, cam, without(scene::Effect::Textures)) == expected);
  CHECK(sequential(textured, cam, scene::EffectSet::all()) != expected);
  checkSortPoints(textured, cam, without(scene::Effect::Textures), expected, "Plan/texture_evaluations_skipped");
}

TEST_CASE("RasterPlan: emission off and direct light off skip their terms, in every sort point") {
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  scene::Scene dark = s;
  for (scene::Material& m : dark.materials) m.emissiveFactor = glm::vec3(0.0f);
  const std::vector<glm::vec3> noEmission = sequential(dark, cam, scene::EffectSet::all());
  CHECK(sequential(s, cam, without(scene::Effect::Emission)) == noEmission);
  checkSortPoints(s, cam, without(scene::Effect::Emission), noEmission, "Plan/emission_skipped");
  // Direct light off: only the emitters show.
  const std::vector<glm::vec3> emissionOnly = sequential(s, cam, without(scene::Effect::DirectLight));
  size_t lit = 0;
  for (size_t i = 0; i < emissionOnly.size(); ++i)
    if (emissionOnly[i] != glm::vec3(0.0f)) ++lit;
  CHECK(lit > 0);
  CHECK(lit < emissionOnly.size() / 10);
  checkSortPoints(s, cam, without(scene::Effect::DirectLight), emissionOnly, "Plan/light_samples_skipped");
}

TEST_CASE("RasterPlan: mirrors under the environment reflect it under the analysed plan, in every sort point") {
  for (const test::ViewedScene& v : test::mirrorsUnderEnvironment()) {
    CAPTURE(v.name);
    const scene::RenderPlan plan = scene::analyzeEffects(v.scene, &v.camera);
    // Only mirrors: no direct light to receive, but the environment's reflection is specular's.
    CHECK_FALSE(plan.on(scene::Effect::DirectLight));
    const std::vector<glm::vec3> all = sequential(v.scene, v.camera, scene::EffectSet::all());
    const std::vector<glm::vec3> planned = sequential(v.scene, v.camera, plan.enabled());
    CHECK(planned == all);
    // The mirror shows its tint of the environment (not black): some pixel is neither sky nor dark.
    size_t tinted = 0;
    for (const glm::vec3& p : planned)
      if (p.x > 0.05f && p.z < 0.9f * p.x) ++tinted;
    CHECK(tinted > planned.size() / 20);
    checkSortPoints(v.scene, v.camera, plan.enabled(), planned, "Plan/light_samples_skipped");
  }
}

}  // namespace pr::raster
