// Tests of pass 1, photon tracing (photonmap/photon_tracer.h): energy conservation in a white
// furnace against the geometric series, the inverse-square irradiance of a point light read
// back from the global map, the caustic map of the bundled Cornell box (specular paths only,
// stored on diffuse surfaces), no caustic photons without specular surfaces or with the plan's
// caustics off, and the same photons in the same order for every P and schedule.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "photonmap/density_estimate.h"
#include "photonmap/photon_pass.h"
#include "photonmap/photon_tracer.h"
#include "raytrace/partition/partition.h"
#include "common/scene/camera_select.h"
#include "raytrace/core/bvh.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "run_record_support.h"
#include "test_support.h"

using namespace pr;

namespace {

constexpr double kPi = 3.14159265358979323846;

scene::Scene furnace(float albedo) {
  scene::Scene s;
  const uint32_t mat = test::addMaterial(s, test::diffuse(albedo));
  test::addSphere(s, glm::vec3(0.0f), 1.0f, 16, mat);
  scene::PunctualLight light;
  light.position = glm::vec3(0.0f);
  light.intensity = 1.0f;
  s.lights.push_back(light);
  return s;
}

// A diffuse square [-h, h]^2 at y = 0 under a point light of intensity 1 at height `height`.
scene::Scene litFloor(float h, float height) {
  scene::Scene s;
  const uint32_t mat = test::addMaterial(s, test::diffuse(0.5f));
  test::addGround(s, h, mat);
  scene::PunctualLight light;
  light.position = glm::vec3(0.0f, height, 0.0f);
  light.intensity = 1.0f;
  s.lights.push_back(light);
  return s;
}

// The irradiance litFloor(h, 1)'s light gives the floor at x: I cos / d^2 with I = 1.
double pointLightIrradiance(const glm::vec3& x) {
  const glm::vec3 toLight = glm::vec3(0, 1, 0) - x;
  const float d = glm::length(toLight);
  return double(toLight.y / d) / double(d * d);
}

// Both maps' photon lists for `global` and `caustic` photons emitted, traced on two PEs.
pm::PhotonLists traceLists(const scene::Scene& s, std::size_t global, std::size_t caustic) {
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = global;
  options.causticPhotons = caustic;
  par::Runtime runtime(2);
  return pm::tracePhotonLists(s, bvh, options, runtime);
}

// The global map's photons of first hits (bounce 0): the direct light, in a kd-tree.
pm::KdTree firstHitMap(const pm::PhotonLists& lists, par::Runtime& runtime) {
  std::vector<pm::Photon> direct;
  for (const pm::Photon& p : lists.global)
    if (p.bounces == 0) direct.push_back(p);
  return pm::KdTree::build(std::move(direct), runtime);
}

scene::Scene cornell() { return scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf"); }

bool sameBytes(const std::vector<pm::Photon>& a, const std::vector<pm::Photon>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(pm::Photon)) == 0);
}

}  // namespace

TEST_CASE("PhotonTracer: white furnace stores the geometric series of the light's power") {
  // A closed diffuse sphere of albedo rho with a point light of intensity I = 1 at its centre:
  // flux Phi = 4 pi I. Every photon is stored at every hit and survives each hit with
  // probability rho at unchanged power, so the power stored at bounce k is Phi rho^k in
  // expectation, and after bounces 0..n it is Phi sum_{k<=n} rho^k. Statistics: photon i
  // contributes C_i = min(G_i, n + 1) stores of Phi / N, G geometric with P(G >= j) = rho^(j-1),
  // so the relative standard error is sd(C) / (E[C] sqrt(N)); the bound is 4 of those plus the
  // RGBE packing error of the (equal) photon powers, 1/255.5 (photon.h).
  const float rho = 0.5f;
  constexpr std::size_t kPhotons = 20000;
  const pm::PhotonLists lists = traceLists(furnace(rho), kPhotons, 0);
  CHECK(lists.caustic.empty());
  CHECK(lists.stats.globalEmitted == kPhotons);
  const double phi = 4.0 * kPi;
  const double n = double(kPhotons);
  std::vector<double> stored(8, 0.0);
  double total = 0.0;
  for (const pm::Photon& p : lists.global) {
    const double power = double(p.powerRgb().x);
    total += power;
    if (p.bounces < stored.size()) stored[p.bounces] += power;
  }
  double cumulative = 0.0, expected = 0.0;
  for (int k = 0; k < 6; ++k) {
    cumulative += stored[std::size_t(k)];
    expected += phi * std::pow(double(rho), k);
    double mean = 0.0, meanSq = 0.0;
    for (int j = 1; j <= k + 1; ++j) {
      mean += std::pow(double(rho), j - 1);
      meanSq += double(2 * j - 1) * std::pow(double(rho), j - 1);
    }
    const double relSe = std::sqrt(meanSq - mean * mean) / (mean * std::sqrt(n));
    const double tolerance = 4.0 * relSe + 1.0 / 255.5;
    const double error = std::fabs(cumulative / expected - 1.0);
    MESSAGE("bounces <= " << k << ": stored " << cumulative << " W, analytic " << expected << " W, relative error "
                          << error << " (bound " << tolerance << ")");
    CHECK(error <= tolerance);
  }
  // All bounces: Phi / (1 - rho); paths cut at 64 bounces lose rho^64 of it.
  const double all = phi / (1.0 - rho);
  MESSAGE("all bounces: stored " << total << " W, analytic " << all << " W");
  CHECK(std::fabs(total / all - 1.0) <= 4.0 * std::sqrt(double(rho)) / std::sqrt(n) + 1.0 / 255.5);
}

TEST_CASE("PhotonTracer: global-map irradiance under a point light is I cos / d^2") {
  // Floor y = 0, light I = 1 at height 1: E(x) = I cos / d^2 = h / d^3. 400k photons of
  // 4 pi / 400k each, half towards the floor; k = 400 photons per estimate. The box estimate
  // over a disc of radius r underestimates E by about (3/4) r^2 / h^2 at the centre (E's
  // curvature), r < 0.1 here, so < 0.8 %; the count noise of unstratified photons would be
  // 1/sqrt(k) = 5 % (one sigma), and stratified emission makes it far smaller. Bound: 5 % per
  // point (measured below 2 %), 2 % on the mean over the points.
  const scene::Scene s = litFloor(4.0f, 1.0f);
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = 400000;
  options.causticPhotons = 1000;
  par::Runtime runtime(2);
  pm::PhotonLists lists = pm::tracePhotonLists(s, bvh, options, runtime);
  CHECK(lists.caustic.empty());
  CHECK(lists.stats.causticEmitted == 0);
  const pm::KdTree map = firstHitMap(lists, runtime);
  pm::DensityOptions density;
  density.k = 400;
  density.maxRadius = 0.5f;
  double meanError = 0.0;
  const glm::vec3 points[] = {{0, 0, 0}, {0.3f, 0, 0}, {0, 0, -0.5f}, {0.6f, 0, 0.4f}, {-0.8f, 0, -0.8f}};
  for (const glm::vec3& x : points) {
    const pm::DensityEstimate e = pm::estimateIrradiance(map, x, glm::vec3(0, 1, 0), density);
    const double error = double(e.irradiance.x) / pointLightIrradiance(x) - 1.0;
    meanError += error / double(std::size(points));
    MESSAGE("x = (" << x.x << ", " << x.z << "): E = " << e.irradiance.x << ", analytic " << pointLightIrradiance(x) << ", error "
                    << error << ", r = " << std::sqrt(e.radiusSq));
    CHECK(std::fabs(error) <= 0.05);
  }
  CHECK(std::fabs(meanError) <= 0.02);
}

TEST_CASE("PhotonTracer: the point light's irradiance is within a tolerance that shrinks as photons are added") {
  // As above, with k growing with the photon count (k = n / 400): the estimate's relative noise
  // is about 1/sqrt(k) unstratified and less with stratified emission, so the bound
  // 1.2/sqrt(k) + 1 % (curvature bias and RGBE) halves with every fourfold count: 0.25 at 10k
  // photons, 0.13 at 40k, 0.07 at 160k (measured 0.14, 0.045, 0.013).
  const scene::Scene s = litFloor(4.0f, 1.0f);
  const rt::Bvh bvh(s);
  par::Runtime runtime(2);
  for (std::size_t count : {10000u, 40000u, 160000u}) {
    pm::PhotonOptions options;
    options.globalPhotons = count;
    options.causticPhotons = 0;
    pm::PhotonLists lists = pm::tracePhotonLists(s, bvh, options, runtime);
    const pm::KdTree map = firstHitMap(lists, runtime);
    pm::DensityOptions density;
    density.k = int(count / 400);
    density.maxRadius = 1.0f;
    const double bound = 1.2 / std::sqrt(double(density.k)) + 0.01;
    double worst = 0.0;
    for (const glm::vec3 x : {glm::vec3(0, 0, 0), glm::vec3(0.3f, 0, 0), glm::vec3(0, 0, -0.5f), glm::vec3(0.6f, 0, 0.4f)}) {
      const double error =
          double(pm::estimateIrradiance(map, x, glm::vec3(0, 1, 0), density).irradiance.x) / pointLightIrradiance(x) - 1.0;
      worst = std::max(worst, std::fabs(error));
    }
    MESSAGE(count << " photons, k = " << density.k << ": worst relative error " << worst << " (bound " << bound << ")");
    CHECK(worst <= bound);
  }
}

TEST_CASE("PhotonTracer: a scene without specular surfaces traces no caustic photons") {
  const scene::Scene s = litFloor(1.0f, 1.0f);
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = 2000;
  options.causticPhotons = 5000;
  par::Runtime runtime(1);
  const pm::PhotonMaps maps = pm::tracePhotons(s, bvh, options, runtime);
  CHECK(maps.stats.causticTargets == 0);
  CHECK(maps.stats.causticEmitted == 0);
  CHECK(maps.stats.causticSkipped == options.causticPhotons);
  CHECK(maps.caustic.empty());
  CHECK(maps.global.size() > 0);
}

TEST_CASE("PhotonTracer: stratified emission gives every direction cell its share when the count is not a square") {
  // 4200 photons of one point light = 64^2 strata + 104 more. The direction of photon j comes
  // from (u, v) by uniformCone: cos theta = 1 - 2u, phi = 2 pi v about the frame of +z, so
  // (u, v) is read back from the direction. Over a 4 x 4 grid of (u, v) cells each holds 256
  // of the strata exactly; the other 104 photons are uniform, Binomial(104, 1/16) per cell:
  // mean 6.5, sd 2.47. Bound: 5 sd. Giving the 104 the first strata again (as before) put
  // 272-288 photons into the four cells of the first v band.
  const scene::Scene s = litFloor(1.0f, 1.0f);
  pm::PhotonOptions options;
  options.globalPhotons = 4200;
  options.causticPhotons = 0;
  const pm::PhotonSource source(s, options);
  REQUIRE(source.emitted(pm::PhotonMapKind::Global) == 4200);
  int counts[4][4] = {};
  const rt::Frame frame(glm::vec3(0.0f, 0.0f, 1.0f));
  for (std::size_t i = 0; i < 4200; ++i) {
    pm::EmittedPhoton e;
    REQUIRE(source.emit(pm::PhotonMapKind::Global, i, e));
    const glm::vec3 local = frame.toLocal(glm::normalize(e.ray.direction));
    const double u = (1.0 - double(local.z)) / 2.0;
    double v = std::atan2(double(local.y), double(local.x)) / (2.0 * kPi);
    if (v < 0.0) v += 1.0;
    ++counts[std::min(3, int(u * 4.0))][std::min(3, int(v * 4.0))];
  }
  const double mean = 256.0 + 104.0 / 16.0, sd = std::sqrt(104.0 / 16.0 * 15.0 / 16.0);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      CAPTURE(a);
      CAPTURE(b);
      CHECK(std::fabs(double(counts[a][b]) - mean) <= 5.0 * sd);
    }
  // The function itself: photons past the grid keep their uniform (u, v).
  CHECK(pm::stratifiedEmission(4100, 4200, 0.3f, 0.7f) == glm::vec2(0.3f, 0.7f));
  CHECK(pm::stratifiedEmission(65, 4200, 0.5f, 0.5f) == glm::vec2(1.5f / 64.0f, 1.5f / 64.0f));
}

namespace {

// The caustic flux a sphere of `material` (radius 0.5, 1 above the floor) focuses onto a
// diffuse floor from a point light above it: the caustic map's power stored on the floor.
double causticFluxOnFloor(const scene::Material& material) {
  scene::Scene s;
  test::addGround(s, 3.0f, test::addMaterial(s, test::diffuse(0.8f)));
  test::addSphere(s, {0.0f, 1.0f, 0.0f}, 0.5f, 32, test::addMaterial(s, material));
  scene::PunctualLight light;
  light.position = glm::vec3(0.3f, 3.0f, 0.0f);
  light.intensity = 10.0f;
  s.lights.push_back(light);
  const pm::PhotonLists lists = traceLists(s, 0, 20000);
  double flux = 0.0;
  for (const pm::Photon& p : lists.caustic)
    if (std::fabs(p.position.y) < 1.0e-3f) flux += double(rt::luminance(p.powerRgb()));
  return flux;
}

}  // namespace

TEST_CASE("PhotonTracer: surfaces that are part diffuse, part specular still cast caustics") {
  // Jensen's Russian roulette over the whole BSDF: a photon the specular part reflects or
  // transmits stays on its caustic path; only one the diffuse part takes ends it. Against the
  // same sphere fully specular (20000 photons each, aimed at the same target):
  //   - glass of transmission 0.9 (base white, so its diffuse part is 0.1): a transmitted
  //     photon passes two interfaces, each going on with probability ~0.9, so about 0.81 of the
  //     clear glass's flux (0.7-0.95 allows for the reflected share and the count noise);
  //   - smooth white plastic (metallic 0, roughness 0, F0 0.04): its caustic follows the white
  //     mirror's paths, each weighted by Schlick's F at its incidence angle, so the ratio is F
  //     averaged over the paths that reach the floor - at least F0 = 0.04, and well below 1,
  //     since light from above reaches the floor only off the sphere's sides, where F rises
  //     steeply at grazing incidence (0.27 measured; bounds 0.03-0.6 allow for the count noise
  //     of the few photons the plastic's specular part takes).
  scene::Material glass = test::diffuse(1.0f);
  glass.specularFactor = 1.0f;
  glass.roughnessFactor = 0.0f;
  glass.transmissionFactor = 1.0f;
  scene::Material partGlass = glass;
  partGlass.transmissionFactor = 0.9f;
  scene::Material mirror = glass;
  mirror.transmissionFactor = 0.0f;
  mirror.metallicFactor = 1.0f;
  scene::Material plastic = glass;
  plastic.transmissionFactor = 0.0f;
  plastic.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  const double clear = causticFluxOnFloor(glass), part = causticFluxOnFloor(partGlass);
  const double white = causticFluxOnFloor(mirror), smooth = causticFluxOnFloor(plastic);
  MESSAGE("caustic flux on the floor: glass " << clear << ", transmission 0.9 " << part << ", mirror " << white
                                              << ", plastic " << smooth);
  REQUIRE(clear > 0.0);
  REQUIRE(white > 0.0);
  CHECK(part / clear >= 0.7);
  CHECK(part / clear <= 0.95);
  CHECK(smooth / white >= 0.03);
  CHECK(smooth / white <= 0.6);
}

TEST_CASE("PhotonTracer: photons are stored on rough metal and not on a mirror, with their directions") {
  // A metal floor under a point light: roughness 0.3 is a glossy lobe, which the estimates
  // weigh by each photon's direction, so every first hit is stored, arriving from the light;
  // roughness 0 is a perfect mirror, where no estimate is read and nothing is stored.
  auto floorOf = [](float roughness) {
    scene::Scene s;
    scene::Material metal;
    metal.baseColorFactor = glm::vec4(0.9f, 0.9f, 0.9f, 1.0f);
    metal.metallicFactor = 1.0f;
    metal.roughnessFactor = roughness;
    test::addGround(s, 1.0f, test::addMaterial(s, metal));
    scene::PunctualLight light;
    light.position = glm::vec3(0.0f, 1.0f, 0.0f);
    s.lights.push_back(light);
    return s;
  };
  constexpr std::size_t kPhotons = 4000;
  const pm::PhotonLists rough = traceLists(floorOf(0.3f), kPhotons, 0);
  const pm::PhotonLists mirror = traceLists(floorOf(0.0f), kPhotons, 0);
  CHECK(mirror.global.empty());
  // Half the point light's photons go downwards; those within the floor's square are stored.
  REQUIRE(rough.global.size() > kPhotons / 8);
  double worst = 1.0;
  for (const pm::Photon& p : rough.global) {
    CHECK(p.bounces == 0);
    worst = std::min(worst, double(glm::dot(p.incoming(), glm::normalize(glm::vec3(0, 1, 0) - p.position))));
  }
  CHECK(worst > std::cos(2.0 * kPi / 180.0));  // the stored direction points back at the light
}

TEST_CASE("PhotonTracer: the Cornell box's caustic map holds specular-path photons on diffuse surfaces") {
  const scene::Scene s = cornell();
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = 5000;
  options.causticPhotons = 20000;
  par::Runtime runtime(2);
  const pm::PhotonLists lists = pm::tracePhotonLists(s, bvh, options, runtime);
  MESSAGE("caustic targets " << lists.stats.causticTargets << ", caustic photons stored " << lists.caustic.size()
                             << " of " << lists.stats.causticEmitted << " emitted; global stored " << lists.global.size());
  CHECK(lists.stats.causticTargets >= 2);
  REQUIRE(lists.caustic.size() > 1000);
  // Each photon lies on a surface with a Lambertian part: a short ray from just off the photon
  // back along its incoming direction hits such a surface at once.
  const float eps = 1.0e-4f * glm::length(s.bounds.extent());
  std::size_t notSpecular = 0, notDiffuse = 0;
  for (const pm::Photon& p : lists.caustic) {
    if (p.bounces < 1 || p.kind() != pm::PhotonMapKind::Caustic) ++notSpecular;
    const glm::vec3 wi = p.incoming();
    rt::Ray ray{p.position + wi * eps, 0.0f, -wi, 2.0f * eps};
    rt::Hit hit;
    if (!bvh.intersect(ray, hit)) {
      ++notDiffuse;
      continue;
    }
    const scene::Material& m = s.materials[s.triangles[hit.triangle].material];
    const float diffuse = (1.0f - m.metallicFactor) * (1.0f - m.transmissionFactor) *
                          std::max(m.baseColorFactor.x, std::max(m.baseColorFactor.y, m.baseColorFactor.z));
    if (!(diffuse > 0.0f)) ++notDiffuse;
  }
  CHECK(notSpecular == 0);
  // Octahedral direction error (< 1 degree) can make the short probe slip past an edge.
  CHECK(notDiffuse <= lists.caustic.size() / 1000);
}

TEST_CASE("PhotonTracer: the plan's caustics off and indirect off skip those photons") {
  const scene::Scene s = cornell();
  const rt::Bvh bvh(s);
  scene::RenderPlan plan = scene::analyzeEffects(s);
  REQUIRE(plan.on(scene::Effect::Caustics));
  plan[scene::Effect::Caustics].on = false;
  pm::PhotonOptions options;
  options.globalPhotons = 2000;
  options.causticPhotons = 3000;
  options.effects = plan.enabled();
  par::Runtime runtime(1);
  pm::PhotonLists lists = pm::tracePhotonLists(s, bvh, options, runtime);
  CHECK(lists.caustic.empty());
  CHECK(lists.stats.causticSkipped == 3000);
  CHECK(lists.global.size() > 0);
  plan[scene::Effect::Caustics].on = true;
  plan[scene::Effect::IndirectDiffuse].on = false;
  options.effects = plan.enabled();
  lists = pm::tracePhotonLists(s, bvh, options, runtime);
  CHECK(lists.global.empty());
  CHECK(lists.stats.globalSkipped == 2000);
  CHECK(lists.caustic.size() > 0);
}

TEST_CASE("PhotonTracer: the maps are the same photons in the same order for every P and schedule") {
  const scene::Scene s = cornell();
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = 6000;
  options.causticPhotons = 4000;
  options.batchSize = 500;  // 20 tasks
  par::Runtime serial(1);
  const pm::PhotonLists reference = pm::tracePhotonLists(s, bvh, options, serial);
  REQUIRE(reference.stats.tasks == 20);
  REQUIRE(!reference.global.empty());
  REQUIRE(!reference.caustic.empty());
  struct Row {
    int pes;
    const char* schedule;
  };
  for (const Row row : {Row{1, "random"}, Row{2, "demand"}, Row{2, "balanced"}, Row{3, "random"}, Row{3, "distributed"}}) {
    CAPTURE(row.pes);
    CAPTURE(row.schedule);
    par::Runtime runtime(row.pes, row.schedule);
    const pm::PhotonLists lists = pm::tracePhotonLists(s, bvh, options, runtime);
    CHECK(sameBytes(lists.global, reference.global));
    CHECK(sameBytes(lists.caustic, reference.caustic));
    // The run record's per-PE counters add up to the maps' figures.
    auto total = [&](const char* name) { return test::counterTotal(runtime.record(), name); };
    CHECK(total("Photons/global_emitted") == double(lists.stats.globalEmitted));
    CHECK(total("Photons/caustic_emitted") == double(lists.stats.causticEmitted));
    CHECK(total("Photons/global_stored") == double(lists.global.size()));
    CHECK(total("Photons/caustic_stored") == double(lists.caustic.size()));
  }
  // The kd-trees built from them agree too.
  par::Runtime two(2, "spiral");
  const pm::PhotonMaps a = pm::tracePhotons(s, bvh, options, serial);
  const pm::PhotonMaps b = pm::tracePhotons(s, bvh, options, two);
  CHECK(sameBytes({a.global.photons().begin(), a.global.photons().end()},
                  {b.global.photons().begin(), b.global.photons().end()}));
  CHECK(sameBytes({a.caustic.photons().begin(), a.caustic.photons().end()},
                  {b.caustic.photons().begin(), b.caustic.photons().end()}));
}

TEST_CASE("PhotonPass: the message-passing pass stores the batch tracer's photons in its order, in every tracer") {
  const scene::Scene s = cornell();
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = 5000;
  options.causticPhotons = 3000;
  par::Runtime serial(1);
  const pm::PhotonLists reference = pm::tracePhotonLists(s, bvh, options, serial);
  REQUIRE(reference.globalNormals.size() == reference.global.size());
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  for (const char* partition : {"sequential", "image-space", "image-space-cached", "object-space", "object"}) {
    CAPTURE(partition);
    par::Runtime runtime(3);
    // Drive the pass through a tracer the way renderRays does for an integrator's pre-pass.
    struct Tracer final : rt::PrePassTracer {
      const scene::Scene& scene;
      const scene::Camera& camera;
      std::string partition;
      par::Runtime& rt;
      Tracer(const scene::Scene& s, const scene::Camera& c, std::string p, par::Runtime& r) : scene(s), camera(c), partition(std::move(p)), rt(r) {}
      void trace(const std::shared_ptr<const rt::Integrator>& program, int tile) override {
        rt::TraceJob job{scene, camera, program->context().width(), program->context().height(), {}};
        job.integrator = program;
        job.assembleImage = false;
        job.options.tileSizePx = tile;
        rt::makePartition(partition)->render(job, rt);
      }
    } tracer(s, cam, partition, runtime);
    const pm::PhotonLists lists = pm::tracePhotonMessages(s, cam, options, tracer, runtime);
    CHECK(sameBytes(lists.global, reference.global));
    CHECK(sameBytes(lists.caustic, reference.caustic));
    CHECK(lists.globalNormals == reference.globalNormals);
    // Photons stored away from PE 0 travelled there as counted messages, 20 + 12 bytes each
    // (photon and normal): exactly those the run record books on PEs 1 and 2.
    uint64_t merged = 0;
    for (const par::StageRecord& stage : runtime.record().stages)
      if (stage.name == "photon merge")
        for (const par::ChannelTraffic& c : stage.channels) merged += c.bytes;
    double elsewhere = 0.0;
    for (const par::CounterRecord& c : runtime.record().counters)
      if (c.name == "Photons/global_stored" || c.name == "Photons/caustic_stored") elsewhere += c.perPe[1] + c.perPe[2];
    CHECK(merged == uint64_t(elsewhere) * 32);
  }
}

TEST_CASE("PhotonTracer: photons from a uniform environment give a plane open to the sky E = pi L") {
  // A ground square under a uniform environment of radiance L: the upper side sees the whole
  // upper hemisphere, E = pi L; the photons of its first hits (bounce 0) estimate it. k = 200:
  // about 7 % noise (1/sqrt(k)) at a point, less on the mean of five points.
  scene::Scene s;
  test::addGround(s, 1.0f, test::addMaterial(s, test::diffuse(0.5f)));
  const float l = 1.5f;
  s.environment = std::make_shared<const scene::Environment>(scene::Environment::uniform(glm::vec3(l), "test"));
  const rt::Bvh bvh(s);
  pm::PhotonOptions options;
  options.globalPhotons = 200000;
  options.causticPhotons = 0;
  par::Runtime runtime(2);
  pm::PhotonLists lists = pm::tracePhotonLists(s, bvh, options, runtime);
  const pm::KdTree map = firstHitMap(lists, runtime);
  REQUIRE(map.size() > 1000);
  pm::DensityOptions density;
  density.k = 200;
  density.maxRadius = 0.5f;
  double mean = 0.0;
  for (const glm::vec3 x : {glm::vec3(0, 0, 0), glm::vec3(0.3f, 0, 0.2f), glm::vec3(-0.4f, 0, 0.1f), glm::vec3(0.1f, 0, -0.5f),
                            glm::vec3(-0.2f, 0, -0.3f)})
    mean += double(pm::estimateIrradiance(map, x, glm::vec3(0, 1, 0), density).irradiance.x) / 5.0;
  CHECK(mean == doctest::Approx(kPi * l).epsilon(0.05));
}
