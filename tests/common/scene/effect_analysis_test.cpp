// EffectAnalysis: each bundled scene gets the plan a person would expect (written out below,
// with the reasons checked for the words that name what decided them); scenes built in code
// exercise each rule (no lights, no specular surface, one convex object); --effects overrides
// say "forced" and keep the analysis; bad override text is an input error naming the effects.
#include <string>

#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "test_support.h"

using namespace pr;
using scene::Effect;

namespace {

struct Expect {
  Effect effect;
  bool on;
  std::vector<std::string> words;  // each must appear in the reason
};

void checkPlan(const scene::RenderPlan& plan, const std::vector<Expect>& expected) {
  REQUIRE(expected.size() == scene::kEffectCount);
  for (const Expect& e : expected) {
    const scene::EffectDecision& d = plan[e.effect];
    CAPTURE(plan.line(e.effect));
    CHECK(bool(d.effect == e.effect));
    CHECK(d.on == e.on);
    CHECK(d.analysed == e.on);
    CHECK_FALSE(d.forced);
    for (const std::string& w : e.words) CHECK(d.reason.find(w) != std::string::npos);
  }
}

scene::RenderPlan bundledPlan(const std::string& file) {
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / file);
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  return scene::analyzeEffects(s, &cam);
}

scene::PunctualLight pointLight(glm::vec3 at) {
  scene::PunctualLight l;
  l.position = at;
  l.intensity = 10.0f;
  return l;
}

}  // namespace

TEST_CASE("EffectAnalysis: the Cornell box with glass and mirror spheres simulates everything but glossy, anisotropy, textures") {
  // Walls diffuse (roughness 1, metallic 0), a mirror sphere (metallic 1, roughness 0), a glass
  // sphere (transmission 1), a ceiling emitter of 2 triangles; no punctual light, no texture.
  checkPlan(bundledPlan("cornell.gltf"),
            {{Effect::DirectLight, true, {"2 emissive triangles light", "diffuse"}},
             {Effect::Shadows, true, {"occluders", "face each other"}},
             {Effect::IdealSpecular, true, {"mirror", "1 object"}},
             {Effect::GlossySpecular, false, {"no material with a glossy lobe"}},
             {Effect::Transmission, true, {"glass", "1 object"}},
             {Effect::Caustics, true, {"mirror", "glass", "emissive triangle"}},
             {Effect::IndirectDiffuse, true, {"white", "red", "green"}},
             {Effect::Anisotropy, false, {"anisotropy"}},
             {Effect::Textures, false, {"no material references a texture"}},
             {Effect::Emission, true, {"light", "2 emissive triangles"}}});
}

TEST_CASE("EffectAnalysis: the all-diffuse Cornell box has no specular, transmission or caustics") {
  checkPlan(bundledPlan("cornell-diffuse.gltf"),
            {{Effect::DirectLight, true, {"2 emissive triangles"}},
             {Effect::Shadows, true, {"occluders"}},
             {Effect::IdealSpecular, false, {"no material with a mirror lobe"}},
             {Effect::GlossySpecular, false, {"no material with a glossy lobe"}},
             {Effect::Transmission, false, {"no transmissive material"}},
             {Effect::Caustics, false, {"no ideal specular or transmissive surface"}},
             {Effect::IndirectDiffuse, true, {"sphere white"}},
             {Effect::Anisotropy, false, {}},
             {Effect::Textures, false, {}},
             {Effect::Emission, true, {"light"}}});
}

TEST_CASE("EffectAnalysis: the hot-spot room has a point light, an area light, glass and mirror spheres") {
  checkPlan(bundledPlan("hotspot.gltf"),
            {{Effect::DirectLight, true, {"1 punctual light", "2 emissive triangles"}},
             {Effect::Shadows, true, {}},
             {Effect::IdealSpecular, true, {"mirror"}},
             {Effect::GlossySpecular, false, {}},
             {Effect::Transmission, true, {"glass"}},
             {Effect::Caustics, true, {"1 punctual light"}},
             {Effect::IndirectDiffuse, true, {"wall"}},
             {Effect::Anisotropy, false, {}},
             {Effect::Textures, false, {}},
             {Effect::Emission, true, {"light"}}});
}

TEST_CASE("EffectAnalysis: without lights nothing transports light, without emitters no emission") {
  scene::Scene s;
  const uint32_t white = test::addMaterial(s, test::diffuse(0.5f));
  test::addGround(s, 2.0f, white);
  test::addSphere(s, {0, 1, 0}, 0.5f, 12, white);
  const scene::RenderPlan plan = scene::analyzeEffects(s);
  for (Effect e : {Effect::DirectLight, Effect::IndirectDiffuse, Effect::Caustics}) {
    CAPTURE(plan.line(e));
    CHECK_FALSE(plan.on(e));
    CHECK(plan[e].reason.find("no light: no punctual lights, no emissive triangles and no environment") != std::string::npos);
  }
  CHECK_FALSE(plan.on(Effect::Shadows));
  CHECK(plan[Effect::Shadows].reason.find("no direct light") != std::string::npos);
  CHECK_FALSE(plan.on(Effect::Emission));
}

TEST_CASE("EffectAnalysis: a diffuse scene with a glossy metal and no mirror or glass plans no caustics") {
  scene::Scene s;
  const uint32_t white = test::addMaterial(s, test::diffuse(0.5f));
  scene::Material brushed = test::diffuse(0.9f);
  brushed.metallicFactor = 1.0f;
  brushed.roughnessFactor = 0.3f;  // >= 0.0316: a glossy lobe, not a mirror
  const uint32_t metal = test::addMaterial(s, brushed);
  test::addGround(s, 2.0f, white);
  test::addSphere(s, {0, 1, 0}, 0.5f, 12, metal);
  s.lights.push_back(pointLight({0, 3, 0}));
  const scene::RenderPlan plan = scene::analyzeEffects(s);
  CHECK_FALSE(plan.on(Effect::Caustics));
  CHECK(plan[Effect::Caustics].reason.find("no ideal specular or transmissive surface") != std::string::npos);
  CHECK(plan.on(Effect::GlossySpecular));
  CHECK_FALSE(plan.on(Effect::IdealSpecular));
  CHECK(plan.on(Effect::Shadows));
  CHECK(plan.on(Effect::IndirectDiffuse));
}

TEST_CASE("EffectAnalysis: one closed convex object under a light has no shadows and no indirect diffuse") {
  scene::Scene s;
  const uint32_t white = test::addMaterial(s, test::diffuse(0.7f));
  test::addSphere(s, {0, 0, 0}, 1.0f, 24, white);
  s.lights.push_back(pointLight({0, 4, 0}));
  const scene::Camera outside = test::perspectiveAt({0, 0, 5}, 0.8f);
  const scene::RenderPlan plan = scene::analyzeEffects(s, &outside);
  CHECK(plan.on(Effect::DirectLight));
  for (Effect e : {Effect::Shadows, Effect::IndirectDiffuse}) {
    CAPTURE(plan.line(e));
    CHECK_FALSE(plan.on(e));
    CHECK(plan[e].reason.find("closed convex surface seen from outside") != std::string::npos);
  }
  // Seen from inside, the sphere lights itself.
  const scene::Camera inside = test::perspectiveAt({0, 0, 0.5f}, 0.8f);
  CHECK(scene::analyzeEffects(s, &inside).on(Effect::IndirectDiffuse));
  // A ground plane under it (its 6 vertices moved to y = -1.5): the sphere shadows the ground
  // and the ground lights the sphere.
  test::addGround(s, 3.0f, white);
  for (size_t i = s.positions.size() - 6; i < s.positions.size(); ++i) s.positions[i].y = -1.5f;
  s.bounds.extend(glm::vec3(0.0f, -1.5f, 0.0f));
  const scene::RenderPlan withGround = scene::analyzeEffects(s, &outside);
  CHECK(withGround.on(Effect::Shadows));
  CHECK(withGround.on(Effect::IndirectDiffuse));
}

TEST_CASE("EffectAnalysis: a single plane has nothing to occlude or bounce light") {
  scene::Scene s;
  test::addGround(s, 2.0f, test::addMaterial(s, test::diffuse(0.5f)));
  s.lights.push_back(pointLight({0, 1, 0}));
  const scene::RenderPlan plan = scene::analyzeEffects(s);
  CHECK(plan.on(Effect::DirectLight));
  CHECK_FALSE(plan.on(Effect::Shadows));
  CHECK_FALSE(plan.on(Effect::IndirectDiffuse));
  CHECK(plan[Effect::IndirectDiffuse].reason.find("one plane") != std::string::npos);
}

TEST_CASE("EffectAnalysis: reflection that leaves the scene sees a light-emitting environment") {
  for (const test::ViewedScene& v : test::mirrorsUnderEnvironment()) {
    CAPTURE(v.name);
    const scene::RenderPlan plan = scene::analyzeEffects(v.scene, &v.camera);
    CAPTURE(plan.line(Effect::IdealSpecular));
    CHECK(plan.on(Effect::IdealSpecular));
    CHECK(plan[Effect::IdealSpecular].reason.find("see the environment") != std::string::npos);
    CHECK_FALSE(plan.on(Effect::DirectLight));  // nothing diffuse or glossy to receive it
    // Without the environment (a point light instead) a lone mirror's reflections see nothing.
    scene::Scene dark = v.scene;
    dark.environment.reset();
    dark.lights.push_back(pointLight({0, 4, 0}));
    CHECK_FALSE(scene::analyzeEffects(dark, &v.camera).on(Effect::IdealSpecular));
  }
}

TEST_CASE("EffectAnalysis: forcing an effect changes its state, says forced and keeps the analysis") {
  const scene::RenderPlan analysed = bundledPlan("cornell-diffuse.gltf");
  const scene::RenderPlan plan =
      scene::applyOverrides(analysed, scene::parseEffectOverrides("caustics=on,indirect=off"));
  CHECK(plan.on(Effect::Caustics));
  CHECK(plan[Effect::Caustics].forced);
  CHECK_FALSE(plan[Effect::Caustics].analysed);
  CHECK(plan[Effect::Caustics].reason == analysed[Effect::Caustics].reason);
  CHECK(plan.line(Effect::Caustics).find("forced on") != std::string::npos);
  CHECK_FALSE(plan.on(Effect::IndirectDiffuse));
  CHECK(plan.line(Effect::IndirectDiffuse).find("forced off") != std::string::npos);
  CHECK_FALSE(plan[Effect::Shadows].forced);
  CHECK(plan.enabled().has(Effect::Caustics));
  CHECK_FALSE(plan.enabled().has(Effect::IndirectDiffuse));
  CHECK(scene::parseEffectOverrides("").empty());
}

TEST_CASE("EffectAnalysis: unknown effects, values and empty items are input errors listing the effects") {
  for (const char* bad : {"bogus=on", "caustics=maybe", "caustics", "caustics=on,,indirect=off", "caustics=on,"}) {
    CAPTURE(bad);
    try {
      scene::parseEffectOverrides(bad);
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string what = e.what();
      CHECK(what.find("--effects") != std::string::npos);
      CHECK(what.find("direct, shadows, specular, glossy, transmission, caustics, indirect, anisotropy, textures, emission") !=
            std::string::npos);
    }
  }
}
