// Tests of pass 2, the photon-map integrator (photonmap/photon_map_integrator.h): the same image
// bit for bit from the sequential tracer, image-space, object-space and object partitioning for
// every P and schedule, the pre-pass included; close to a long path-traced reference of the bundled
// Cornell box; a render with the plan's caustics off equals one without caustic photons; the
// map views show their maps; the pre-pass's records and rays reach the run record.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "common/parallel/metrics.h"
#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "photonmap/photon_map_integrator.h"
#include "raytrace/core/bvh.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"
#include "run_record_support.h"
#include "test_support.h"

using namespace pr;

namespace {

constexpr int kW = 40, kH = 30;

scene::Scene cornell() { return scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf"); }

pm::PhotonMapSettings smallSettings() {
  pm::PhotonMapSettings s;
  s.globalPhotons = 20000;
  s.causticPhotons = 20000;
  s.photonBatch = 2000;
  s.gatherRays = 64;
  s.fallbackGatherRays = 16;
  return s;
}

image::Image render(const scene::Scene& s, const pm::PhotonMapSettings& settings, std::string_view partition, int pes,
                    const std::string& schedule, int spp = 1, scene::EffectSet effects = scene::EffectSet::all(),
                    par::Runtime* runtime = nullptr) {
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  rt::IntegratorOptions io;
  io.spp = spp;
  io.effects = effects;
  rt::TraceJob job{s, cam, kW, kH, {}};
  job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, kW, kH, io, settings);
  job.options.tileSizePx = 8;
  par::Runtime own(pes, schedule);
  return rt::renderRays(job, partition, runtime ? *runtime : own).image;
}

// Over the pixels that do not see the light itself (reference below 2 in every channel): at
// this resolution its pixels are partly covered, and their values are sampling noise in both.
bool seesLight(const glm::vec3& reference) { return reference.x > 2.0f || reference.y > 2.0f || reference.z > 2.0f; }

double meanLuminance(const image::Image& img, const image::Image* mask = nullptr) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    if (mask && seesLight(mask->pixels[i])) continue;
    const glm::vec3& p = img.pixels[i];
    sum += 0.2126 * p.x + 0.7152 * p.y + 0.0722 * p.z;
    ++n;
  }
  return n ? sum / double(n) : 0.0;
}

double rmse(const image::Image& a, const image::Image& reference) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    if (seesLight(reference.pixels[i])) continue;
    const glm::vec3 d = a.pixels[i] - reference.pixels[i];
    sum += double(glm::dot(d, d)) / 3.0;
    ++n;
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

double counter(const par::Runtime& rt, const std::string& name) { return test::counterTotal(rt.record(), name); }

}  // namespace

TEST_CASE("PhotonMapIntegrator: sequential and image-space give the same image for every P and schedule") {
  const scene::Scene s = cornell();
  const image::Image reference = render(s, smallSettings(), "sequential", 1, "demand");
  REQUIRE(meanLuminance(reference) > 0.05);
  struct Row {
    int pes;
    const char* schedule;
  };
  for (const Row row : {Row{1, "demand"}, Row{2, "demand"}, Row{2, "balanced"}, Row{3, "random"}, Row{4, "distributed"}}) {
    CAPTURE(row.pes);
    CAPTURE(row.schedule);
    const image::Image img = render(s, smallSettings(), "image-space", row.pes, row.schedule);
    CHECK(img.pixels == reference.pixels);
  }
}

TEST_CASE("PhotonMapIntegrator: image-space-cached, object-space and object partitioning give the sequential image, pre-pass and all") {
  const scene::Scene s = cornell();
  const image::Image reference = render(s, smallSettings(), "sequential", 1, "demand");
  for (const char* partition : {"image-space-cached", "object-space", "object"})
    for (int pes : {1, 2, 3}) {
      CAPTURE(partition);
      CAPTURE(pes);
      CHECK(render(s, smallSettings(), partition, pes, "demand").pixels == reference.pixels);
    }
}

TEST_CASE("PhotonMapIntegrator: the partitioned pre-pass reads no geometry a PE does not hold") {
  // Each PE shades from a copy of the scene whose foreign triangles are NaN: a photon, probe or
  // gather path read anywhere but at the owner would change the image.
  const scene::Scene s = cornell();
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  const image::Image reference = render(s, smallSettings(), "sequential", 1, "demand");
  for (const char* partition : {"image-space-cached", "object-space", "object"}) {
    CAPTURE(partition);
    rt::TraceJob job{s, cam, kW, kH, {}};
    job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, kW, kH, rt::IntegratorOptions{}, smallSettings());
    job.options.tileSizePx = 8;
    job.options.poisonForeignGeometry = true;
    par::Runtime runtime(3);
    CHECK(rt::renderRays(job, partition, runtime).image.pixels == reference.pixels);
  }
}

TEST_CASE("PhotonMapIntegrator: the Cornell box is close to a long path-traced reference") {
  const scene::Scene s = cornell();
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  rt::TraceOptions path;
  path.integrator.kind = rt::IntegratorKind::Path;
  path.integrator.spp = 1024;
  path.integrator.maxDepth = rt::IntegratorOptions{}.maxDepth;  // the photon map's (render below)
  par::Runtime runtime(2);
  const image::Image reference = rt::renderRays(s, cam, kW, kH, path, "image-space", runtime).image;
  pm::PhotonMapSettings settings = smallSettings();
  settings.globalPhotons = 100000;
  settings.causticPhotons = 100000;
  settings.gatherRays = 256;
  const image::Image photon = render(s, settings, "image-space", 2, "demand", 4);
  const double mean = meanLuminance(reference, &reference);
  CAPTURE(mean);
  CAPTURE(meanLuminance(photon, &reference));
  CAPTURE(rmse(photon, reference));
  // The estimates' bias is small against the image: mean within 5 % (1 % at 200k photons and a
  // 4096-spp reference), RMSE, mostly the path tracer's own noise at this spp, under 0.3 x the
  // mean (0.18 against the 4096-spp reference).
  CHECK(meanLuminance(photon, &reference) == doctest::Approx(mean).epsilon(0.05));
  CHECK(rmse(photon, reference) < 0.3 * mean);
}

namespace {

// Both renderers' path depth in the comparisons below: photonMapped's eye paths end where
// pathTraced's do (the default 8 against 16 left the photon map 3 % dark on a frosted sphere,
// whose light comes along long chains of internal reflections).
constexpr int kReferenceDepth = 16;

// A square n x n path-traced reference of (s, cam) at `spp`, depth kReferenceDepth, image-space.
image::Image pathTraced(const scene::Scene& s, const scene::Camera& cam, int n, int spp, par::Runtime& runtime,
                        scene::EffectSet effects = scene::EffectSet::all()) {
  rt::TraceOptions path;
  path.integrator.kind = rt::IntegratorKind::Path;
  path.integrator.spp = spp;
  path.integrator.maxDepth = kReferenceDepth;
  path.integrator.effects = effects;
  return rt::renderRays(s, cam, n, n, path, "image-space", runtime).image;
}

// The photon map's n x n image of (s, cam) with `settings` at `spp`, depth kReferenceDepth, image-space.
image::Image photonMapped(const scene::Scene& s, const scene::Camera& cam, int n, const pm::PhotonMapSettings& settings, int spp,
                          par::Runtime& runtime, scene::EffectSet effects = scene::EffectSet::all()) {
  rt::IntegratorOptions io;
  io.spp = spp;
  io.effects = effects;
  io.maxDepth = kReferenceDepth;  // the path tracer's: the paths each leaves out must be the same
  rt::TraceJob job{s, cam, n, n, {}};
  job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, n, n, io, settings);
  return rt::renderRays(job, "image-space", runtime).image;
}

// Every 8x8 block of `image` within `tolerance` (relative) of the reference's; reports the worst.
void checkBlocks(const image::Image& image, const image::Image& reference, double tolerance) {
  const int w = reference.width, h = reference.height;
  double worst = 0.0;
  for (int by = 0; by + 8 <= h; by += 8)
    for (int bx = 0; bx + 8 <= w; bx += 8) {
      double a = 0.0, b = 0.0;
      for (int y = by; y < by + 8; ++y)
        for (int x = bx; x < bx + 8; ++x) {
          a += double(rt::luminance(image.pixels[std::size_t(y * w + x)]));
          b += double(rt::luminance(reference.pixels[std::size_t(y * w + x)]));
        }
      CAPTURE(bx);
      CAPTURE(by);
      REQUIRE(b > 0.0);
      worst = std::max(worst, std::fabs(a / b - 1.0));
      CHECK(a == doctest::Approx(b).epsilon(tolerance));
    }
  MESSAGE("worst 8x8 block: " << worst * 100.0 << " %");
}

}  // namespace

TEST_CASE("PhotonMapIntegrator: a wall lit through a rough metal is within 3 % of a long path trace, block by block") {
  // A diffuse wall and floor, a point light, and facing the wall a rough metal plate (roughness
  // 0.3) that throws the light's glossy reflection onto it: an L G D path, about a tenth of the
  // wall's light. The camera sees the wall and floor. Without glossy photons, gather rays found
  // the metal black and the wall came out dark; read by gathering, the metal's highlight is
  // sampled by few gather rays and the blocks scatter by +-7 %; as a glossy caustic read
  // where it lands, the photon map at its default photon and gather counts is within 3 %
  // (2.2 % measured). The reference's own noise is about 0.6 % per block at 8192 spp.
  scene::Scene s;
  const std::uint32_t wall = test::addMaterial(s, test::diffuse(0.7f));
  scene::Material rough;
  rough.baseColorFactor = glm::vec4(0.9f, 0.9f, 0.9f, 1.0f);
  rough.metallicFactor = 1.0f;
  rough.roughnessFactor = 0.3f;
  const std::uint32_t metal = test::addMaterial(s, rough);
  test::addGround(s, 2.0f, wall);
  test::addTri(s, {-2, 0, -1}, {2, 0, -1}, {2, 2.5f, -1}, wall);  // facing +z
  test::addTri(s, {-2, 0, -1}, {2, 2.5f, -1}, {-2, 2.5f, -1}, wall);
  test::addTri(s, {-1.5f, 0, 1.2f}, {-1.5f, 2.5f, 1.2f}, {1.5f, 2.5f, 1.2f}, metal);  // facing -z
  test::addTri(s, {-1.5f, 0, 1.2f}, {1.5f, 2.5f, 1.2f}, {1.5f, 0, 1.2f}, metal);
  scene::PunctualLight light;
  light.position = glm::vec3(0.0f, 2.0f, 0.2f);
  light.intensity = 4.0f;
  s.lights.push_back(light);
  const scene::Camera cam = test::perspectiveAt({0.0f, 1.0f, 0.8f}, 1.2f);
  constexpr int kN = 32;

  par::Runtime runtime(2);
  const image::Image reference = pathTraced(s, cam, kN, 8192, runtime);
  pm::PhotonMapSettings settings = smallSettings();
  settings.globalPhotons = 200000;
  settings.gatherRays = 256;
  const image::Image photon = photonMapped(s, cam, kN, settings, 4, runtime);

  checkBlocks(photon, reference, 0.03);
}

TEST_CASE("PhotonMapIntegrator: a floor under the default 4 % dielectric layer, lit only by a wall, matches a long path trace") {
  // A rough floor (roughness 1) that keeps the glTF default Fresnel layer, lit only by light off
  // a Lambertian wall (the sun shines along the floor, onto the wall), seen at grazing angles,
  // where the layer takes most off the diffuse part under it (fresnel_mix). The path tracer
  // weighs each direction exactly; the cached irradiance has no directions, so the photon map
  // lights the base by the weight's cosine-weighted mean over incoming directions. This floor is
  // that mean's worst case - all its light comes from the wall opposite the eye, where F(wo.h) is
  // near its largest - and the blocks come out up to 6.0 % bright (measured; the same floor
  // without the layer: within 2.6 %); without the layer's weight on the cached light, 12 %.
  scene::Scene s;
  const std::uint32_t wall = test::addMaterial(s, test::diffuse(0.7f));
  scene::Material layered;
  layered.baseColorFactor = glm::vec4(0.7f, 0.7f, 0.7f, 1.0f);
  layered.metallicFactor = 0.0f;
  layered.roughnessFactor = 1.0f;
  const std::uint32_t floor = test::addMaterial(s, layered);
  test::addGround(s, 2.0f, floor);
  test::addTri(s, {-2, 0, -1}, {2, 0, -1}, {2, 2.5f, -1}, wall);  // facing +z
  test::addTri(s, {-2, 0, -1}, {2, 2.5f, -1}, {-2, 2.5f, -1}, wall);
  scene::PunctualLight sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::vec3(0.0f, 0.0f, -1.0f);
  sun.intensity = 2.0f;
  s.lights.push_back(sun);
  const scene::Camera cam = test::perspectiveAt({0.0f, 0.3f, 1.9f}, 0.5f);
  constexpr int kN = 32;

  par::Runtime runtime(2);
  const image::Image reference = pathTraced(s, cam, kN, 8192, runtime);
  pm::PhotonMapSettings settings = smallSettings();
  settings.globalPhotons = 200000;
  settings.gatherRays = 256;
  const image::Image photon = photonMapped(s, cam, kN, settings, 4, runtime);
  checkBlocks(photon, reference, 0.08);
}

namespace {

// A sphere of `material` (radius 0.5, centre 1 above a diffuse floor) under a small square area
// light 3 above the floor, seen by the light through a square hole in a black screen just below
// it: the floor gets direct light only in a thin ring around the sphere's shadow, so light that
// reaches it off the lit floor and then the sphere (L D S D, a caustic path to the path tracer's
// plan too) is small beside the caustic. An orthographic camera 45 degrees above the floor
// looks down -x at the floor point (x, 0, 0), which at that angle the sphere does not hide:
// x = 0 is the focus of a glass sphere inside its shadow; a smooth plastic's caustic is a ring
// outside the shadow (light off its sides, where Fresnel reflection is strong), which the
// window (0.8 x 0.8) at x = 1.2 crosses.
struct CausticStage {
  scene::Scene scene;
  scene::Camera camera;
};

CausticStage causticStage(const scene::Material& material, float x, bool screen = true) {
  CausticStage stage;
  scene::Scene& s = stage.scene;
  test::addGround(s, 3.0f, test::addMaterial(s, test::diffuse(0.8f)));
  test::addSphere(s, {0.0f, 1.0f, 0.0f}, 0.5f, 48, test::addMaterial(s, material));
  // Without the screen, a light five times as wide (as bright in all).
  const float half = screen ? 0.15f : 0.75f;
  scene::Material emitter = test::diffuse(0.0f);
  emitter.emissiveFactor = glm::vec3(1.0f);
  emitter.emissiveStrength = 200.0f * (0.15f / half) * (0.15f / half);
  const std::uint32_t light = test::addMaterial(s, emitter);
  test::addTri(s, {-half, 3, -half}, {half, 3, half}, {-half, 3, half}, light);  // facing down
  test::addTri(s, {-half, 3, -half}, {half, 3, -half}, {half, 3, half}, light);
  test::addAreaLights(s, light);
  // The screen at y = 2.5 facing up, with a hole 0.3 across: four quads around it.
  const std::uint32_t black = test::addMaterial(s, test::diffuse(0.0f));
  auto quad = [&](float x0, float z0, float x1, float z1) {
    test::addTri(s, {x0, 2.5f, z0}, {x0, 2.5f, z1}, {x1, 2.5f, z1}, black);
    test::addTri(s, {x0, 2.5f, z0}, {x1, 2.5f, z1}, {x1, 2.5f, z0}, black);
  };
  const float e = 3.0f, hole = 0.15f;
  if (screen) {
    quad(-e, -e, e, -hole);
    quad(-e, hole, e, e);
    quad(-e, -hole, -hole, hole);
    quad(hole, -hole, e, hole);
  }
  scene::Camera& c = stage.camera;
  c.projection = scene::Projection::Orthographic;
  c.xmag = c.ymag = 0.4f;
  const float h = 0.70710678f;
  c.cameraToWorld = glm::mat4(glm::vec4(0, 0, -1, 0), glm::vec4(-h, h, 0, 0), glm::vec4(h, h, 0, 0), glm::vec4(x + 3 * h, 3 * h, 0, 1));
  return stage;
}

double meanOf(const image::Image& img) {
  double sum = 0.0;
  for (const glm::vec3& p : img.pixels) sum += double(rt::luminance(p));
  return sum / double(img.pixels.size());
}

}  // namespace

TEST_CASE("PhotonMapIntegrator: the caustics of part glass and smooth plastic match the path tracer, closer with more photons") {
  // The caustics of a sphere of glass with transmission 0.9 and of one of smooth white plastic
  // (a 4 % Fresnel layer over a diffuse base): each renderer's image with caustics less its
  // image with the plan's caustics off (both then end specular rays after a diffuse or glossy
  // bounce; the photon map reads no caustic map), against a long path trace. The bound shrinks
  // as 1 / sqrt(n), n the caustic photons stored in the window's footprint (the density
  // estimate's count noise), to a floor of 4 % for what does not shrink with photons (the
  // reference's noise).
  // The global radius is set below the sphere's: the automatic one (5 % of the scene's
  // diagonal, 0.45 here) is near the sphere's radius, and its disc test drops photons of so
  // curved a surface, which darkens the indirect light under the plastic sphere by a third.
  scene::Material partGlass = test::diffuse(1.0f);
  partGlass.specularFactor = 1.0f;
  partGlass.roughnessFactor = 0.0f;
  partGlass.transmissionFactor = 0.9f;
  scene::Material plastic = partGlass;
  plastic.transmissionFactor = 0.0f;
  plastic.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  constexpr int kN = 24;
  scene::EffectSet noCaustics = scene::EffectSet::all();
  noCaustics.set(scene::Effect::Caustics, false);
  struct Case {
    std::string name;
    scene::Material material;
    float x;
    std::size_t photons;  // the fewest caustic photons tried (then 4 and 16 times as many)
  };
  for (const Case& c : {Case{"transmission 0.9", partGlass, 0.0f, 2500}, Case{"smooth plastic", plastic, 1.2f, 20000}}) {
    const std::string& name = c.name;
    CAPTURE(name);
    const CausticStage stage = causticStage(c.material, c.x);
    par::Runtime runtime(2);
    auto pathMean = [&](scene::EffectSet effects) {
      return meanOf(pathTraced(stage.scene, stage.camera, kN, 4096, runtime, effects));
    };
    auto photonMean = [&](std::size_t photons, scene::EffectSet effects) {
      pm::PhotonMapSettings settings = smallSettings();
      settings.causticPhotons = photons;
      settings.globalRadius = 0.1f;
      return meanOf(photonMapped(stage.scene, stage.camera, kN, settings, 4, runtime, effects));
    };
    const double reference = pathMean(scene::EffectSet::all()) - pathMean(noCaustics);
    const double withoutCaustics = photonMean(0, noCaustics);
    REQUIRE(reference > 0.0);
    const rt::Bvh bvh(stage.scene);
    for (std::size_t photons : {c.photons, 4 * c.photons, 16 * c.photons}) {
      // The caustic photons the window's footprint on the floor holds: their count's relative
      // noise is 1 / sqrt(count).
      pm::PhotonOptions options;
      options.globalPhotons = 0;
      options.causticPhotons = photons;
      par::Runtime tracing(1);
      std::size_t inWindow = 0;
      for (const pm::Photon& p : pm::tracePhotonLists(stage.scene, bvh, options, tracing).caustic)
        inWindow += std::fabs(p.position.y) < 1.0e-3f && std::fabs(p.position.x - c.x) <= 0.4f * std::sqrt(2.0f) &&
                    std::fabs(p.position.z) <= 0.4f;
      const double caustic = photonMean(photons, scene::EffectSet::all()) - withoutCaustics;
      const double error = std::fabs(caustic / reference - 1.0);
      const double bound = 0.04 + 3.0 / std::sqrt(double(std::max<std::size_t>(inWindow, 1)));
      MESSAGE(name << ", " << photons << " caustic photons (" << inWindow << " in the window): caustic " << caustic
                   << ", path tracer's " << reference << ", error " << error * 100.0 << " % (bound " << bound * 100.0 << " %)");
      CHECK(error <= bound);
    }
  }
}

TEST_CASE("PhotonMapIntegrator: frosted, partly transmissive glass matches the path tracer, seen, from inside and in its light") {
  // A sphere of frosted glass (roughness 0.3, transmission 0.8 over a white diffuse fifth) under
  // a wide area light: the light it scatters onto the floor inside its shadow is a glossy path
  // (L G D), carried by the global map's photons that passed through it and read where it
  // lands; the sphere seen by the eye is refracted about sampled microfacet normals, as the path
  // tracer refracts it (before, both passes refracted it as smooth glass); and seen from inside
  // it, its diffuse fifth shows the light refracted into it, whose radiance the refraction
  // raised by eta^2 (flux in the photons, radiance in the eye paths: before, eye paths left
  // the factor out, so the photon map's light inside a solid seen from outside was 30 % bright
  // and the path tracer's camera inside one saw it 2.25 times too dark). The photon map takes 64
  // samples: the light its eye paths find through the sphere comes along rare paths, whose noise
  // at 16 was 5 % of the sphere's mean.
  scene::Material frosted = test::diffuse(0.9f);
  frosted.specularFactor = 1.0f;
  frosted.roughnessFactor = 0.3f;
  frosted.transmissionFactor = 0.8f;
  CausticStage floor = causticStage(frosted, 0.0f, false);
  CausticStage sphere = floor, inside = floor;
  sphere.camera = test::perspectiveAt({0.0f, 1.2f, 3.0f}, 0.4f);
  inside.camera = test::perspectiveAt({0.0f, 1.0f, 0.0f}, 0.8f);
  constexpr int kN = 24;
  par::Runtime runtime(2);
  for (const CausticStage* stage : {&floor, &sphere, &inside}) {
    const std::string view = stage == &floor ? "the floor under it" : stage == &sphere ? "the sphere" : "inside the sphere";
    CAPTURE(view);
    pm::PhotonMapSettings settings = smallSettings();
    settings.globalPhotons = 400000;
    settings.globalRadius = 0.1f;
    const double a = meanOf(photonMapped(stage->scene, stage->camera, kN, settings, 64, runtime));
    const double b = meanOf(pathTraced(stage->scene, stage->camera, kN, 2048, runtime));
    MESSAGE(view << ": photon map " << a << ", path tracer " << b << ", " << (a / b - 1.0) * 100.0 << " %");
    REQUIRE(b > 0.0);
    CHECK(std::fabs(a / b - 1.0) <= 0.05);
  }
}

TEST_CASE("PhotonMapIntegrator: caustics off drops the caustic map and the gathers' paths through mirrors and glass") {
  // With the plan's caustics off the photon map, like the path tracer, ends a ray at an ideal
  // specular surface after a diffuse or glossy bounce: besides the caustic map (L S+ D), the
  // light gather rays found through the Cornell box's mirror and glass sphere (L D S D) is gone,
  // so the image is darker than one that only traced no caustic photons, itself darker than
  // the full render.
  const scene::Scene s = cornell();
  scene::EffectSet noCaustics = scene::EffectSet::all();
  noCaustics.set(scene::Effect::Caustics, false);
  par::Runtime runtime(2);
  const image::Image off = render(s, smallSettings(), "image-space", 2, "demand", 1, noCaustics, &runtime);
  CHECK(counter(runtime, "Plan/caustic_rays_skipped") > 0.0);
  pm::PhotonMapSettings none = smallSettings();
  none.causticPhotons = 0;
  const double withoutPhotons = meanLuminance(render(s, none, "image-space", 2, "demand"));
  const double full = meanLuminance(render(s, smallSettings(), "image-space", 2, "demand"));
  CAPTURE(withoutPhotons);
  CAPTURE(full);
  CHECK(meanLuminance(off) < 0.999 * withoutPhotons);
  CHECK(withoutPhotons < 0.999 * full);
}

TEST_CASE("PhotonMapIntegrator: the map views show the maps, the caustic map far sparser") {
  const scene::Scene s = cornell();
  pm::PhotonMapSettings settings = smallSettings();
  settings.view = pm::PhotonView::GlobalMap;
  const image::Image global = render(s, settings, "image-space", 2, "demand");
  settings.view = pm::PhotonView::CausticMap;
  const image::Image caustic = render(s, settings, "image-space", 2, "demand");
  auto lit = [](const image::Image& img) {
    size_t n = 0;
    for (const glm::vec3& p : img.pixels) n += (p.x + p.y + p.z) > 0.0f ? 1 : 0;
    return n;
  };
  CHECK(lit(global) > size_t(kW * kH) / 2);
  CHECK(lit(caustic) > 0);
  CHECK(meanLuminance(caustic) < 0.5 * meanLuminance(global));
  CHECK(bool(pm::parsePhotonView("caustic-map") == pm::PhotonView::CausticMap));
  CHECK_THROWS_AS(pm::parsePhotonView("photons"), InputError);
}

TEST_CASE("PhotonMapIntegrator: the pre-pass's photons, records and gather rays are run-record counters") {
  const scene::Scene s = cornell();
  par::Runtime runtime(2);
  render(s, smallSettings(), "image-space", 2, "demand", 1, scene::EffectSet::all(), &runtime);
  const double records = counter(runtime, "IrradianceCache/records");
  CHECK(records > 0);
  CHECK(records < 0.5 * kW * kH);  // gathering at a fraction of the pixels
  // Probes that found a diffuse surface: most pixels (not the light, the open front, glass).
  CHECK(counter(runtime, "IrradianceCache/probes") > 0.5 * kW * kH);
  CHECK(counter(runtime, "IrradianceCache/probes") <= kW * kH);
  CHECK(counter(runtime, "IrradianceCache/gather_hits") >= records * 30);
  CHECK(counter(runtime, "Photons/global_stored") > 0);
  // The cache's levels ran as stages of their own.
  bool cacheStage = false;
  for (const par::StageRecord& stage : runtime.record().stages) cacheStage |= stage.name == "irradiance-cache records 1/16";
  CHECK(cacheStage);
}


TEST_CASE("PhotonMapIntegrator: each bundled scene's analysed plan renders the all-on image bit for bit") {
  // What the analysis turns off cannot appear: skipping it (no caustic photons in the diffuse
  // box, for one) changes the work, never the image.
  for (const char* file : {"cornell.gltf", "cornell-diffuse.gltf", "hotspot.gltf"}) {
    CAPTURE(file);
    const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / file);
    const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
    const scene::RenderPlan plan = scene::analyzeEffects(s, &cam);
    par::Runtime analysed(2);
    const image::Image a = render(s, smallSettings(), "image-space", 2, "demand", 1, plan.enabled(), &analysed);
    const image::Image all = render(s, smallSettings(), "image-space", 2, "demand", 1, scene::EffectSet::all());
    CHECK(a.pixels == all.pixels);
    if (!plan.on(scene::Effect::Caustics)) CHECK(counter(analysed, "Photons/caustic_emitted") == 0);
  }
}

TEST_CASE("PhotonMapIntegrator: mirrors under the environment keep their reflections under the analysed plan") {
  for (const test::ViewedScene& v : test::mirrorsUnderEnvironment()) {
    CAPTURE(v.name);
    const scene::RenderPlan plan = scene::analyzeEffects(v.scene, &v.camera);
    rt::IntegratorOptions io;
    io.effects = plan.enabled();
    auto renderWith = [&](scene::EffectSet effects) {
      io.effects = effects;
      rt::TraceJob job{v.scene, v.camera, kW, kH, {}};
      job.integrator = std::make_shared<const pm::PhotonMapIntegrator>(v.scene, v.camera, kW, kH, io, smallSettings());
      job.options.tileSizePx = 8;
      par::Runtime runtime(2);
      return rt::renderRays(job, "image-space", runtime);
    };
    const rt::TraceResult planned = renderWith(plan.enabled());
    const rt::TraceResult all = renderWith(scene::EffectSet::all());
    CHECK(planned.image.pixels == all.image.pixels);
    CHECK(planned.rays.specularRaysSkipped == 0);
  }
}

TEST_CASE("PhotonMapIntegrator: the scene is broadcast once per render, the pre-passes' merged results besides it") {
  // Image-space with the photon map: the scene and BVH (as a path-traced render broadcasts
  // them) once - not again per program - and each merge of per-PE results once (the photons,
  // the precomputed points, the probes, each cache level's coverage, samples and records),
  // from which every PE derives the maps and the cache: at least their bytes reach PE 1.
  const scene::Scene s = cornell();
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  auto broadcastPerPe = [](const par::Runtime& rt) {  // to PE 1, which receives them all
    return par::summarize(rt.record()).total.figure("broadcastBytesReceived").max;
  };
  par::Runtime pathRuntime(2);
  rt::TraceOptions path;
  path.tileSizePx = 8;
  rt::renderRays(s, cam, kW, kH, path, "image-space", pathRuntime);
  const double scene = broadcastPerPe(pathRuntime);
  par::Runtime runtime(2);
  rt::TraceJob job{s, cam, kW, kH, {}};
  const auto integrator = std::make_shared<const pm::PhotonMapIntegrator>(s, cam, kW, kH, rt::IntegratorOptions{}, smallSettings());
  job.integrator = integrator;
  job.options.tileSizePx = 8;
  rt::renderRays(job, "image-space", runtime);
  const double replicated = double(integrator->maps().global.bytes() + integrator->maps().caustic.bytes() +
                                   integrator->precomputedIrradiance().bytes() + integrator->cache().bytes());
  CHECK(counter(runtime, "IrradianceCache/records") > 0.0);
  const double got = broadcastPerPe(runtime);
  CHECK(got >= scene + replicated);
  std::uint64_t merges = 0, received = 0;
  for (const par::StageRecord& st : runtime.record().stages) {
    if (st.name.find("merge") != std::string::npos) ++merges;
    received += st.pes[1].broadcastsReceived;
  }
  CHECK(merges >= 6);
  CHECK(received == 1 + merges);
}
