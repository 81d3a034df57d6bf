// The sweep's series (see sweep.h).
#include "tools/sweep/sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/image/image_io.h"
#include "common/parallel/process_group.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "raytrace/integrators/sampling.h"
#include "tools/render_methods.h"
#include "tools/timed_render.h"

namespace pr::cli {

std::string formatValue(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

namespace {

struct Context {
  const SweepSpec& args;
  RenderInput input;
};

// One timed render of the series: a fresh runtime, CPU time of the whole process (every PE).
SweepTimed render(const Context& c, const RenderSettings& settings) {
  TimedRender t = timedRender(findRenderMethod(c.args.method), c.input, settings, everyRank(c.args.threads), c.args.schedule);
  return SweepTimed{std::move(t.outcome.image), t.cpuSeconds, t.wallSeconds};
}

RenderSettings baseSettings(const SweepSpec& a, const std::string& integrator, int spp, std::uint64_t seed, int depth) {
  RenderSettings s;
  s.ray.integrator = integrator;
  s.ray.spp = spp;
  s.ray.maxDepth = depth;
  s.ray.seed = seed;
  s.ray.photonmap = a.photonmap;
  return s;
}

// The photon map with the varied setting at `value`.
void applyVaried(const std::string& vary, double value, RenderSettings& s) {
  pm::PhotonMapSettings& p = s.ray.photonmap;
  if (vary == "photons") {
    const double ratio = p.globalPhotons > 0 ? double(p.causticPhotons) / double(p.globalPhotons) : 0.5;
    p.globalPhotons = std::size_t(value);
    p.causticPhotons = std::size_t(value * ratio);
  } else if (vary == "gather") {
    p.gatherRays = int(value);
  } else if (vary == "spp") {
    s.ray.spp = int(value);
  } else if (vary == "k") {
    p.globalK = int(value);
  } else if (vary == "radius") {
    p.globalRadius = float(value);
  } else if (vary == "cache-accuracy") {
    p.cacheAccuracy = float(value);
  } else if (vary == "irradiance-stride") {
    p.irradianceStride = int(value);
  }
}

// The values a varied setting takes: (least, most], or [least, most] where least is allowed.
struct VariedRange {
  double least = 0.0;
  bool leastAllowed = false;
  double most = 1e30;
  bool integral = true;
};

VariedRange variedRange(const std::string& vary) {
  if (vary == "photons") return {0.0, false, 1e8, true};
  if (vary == "gather") return {0.0, false, 65536.0, true};
  if (vary == "spp") return {0.0, false, double(rt::kMaxSpp), true};
  if (vary == "k") return {0.0, false, 10000.0, true};
  if (vary == "cache-accuracy") return {0.001, true, 1.0, false};
  if (vary == "irradiance-stride") return {0.0, true, 1024.0, true};  // 0: no precomputed irradiance
  return {0.0, false, 1e30, false};                                   // radius
}

std::vector<double> defaultValues(const std::string& vary, const scene::Scene& scene) {
  if (vary == "photons") return {25000, 50000, 100000, 200000, 400000};
  if (vary == "gather") return {32, 64, 128, 256, 512};
  if (vary == "spp") return {1, 2, 4, 8, 16};
  if (vary == "k") return {25, 50, 100, 200};
  if (vary == "cache-accuracy") return {0.5, 0.25, 0.125, 0.0625};
  if (vary == "irradiance-stride") return {16, 4, 1, 0};
  const float diagonal = glm::length(scene.bounds.extent());
  return {0.02 * diagonal, 0.05 * diagonal, 0.1 * diagonal};
}



// The CPU seconds at which an integrator's curve (rows by increasing cost) first reaches the
// target RMSE, by log-log interpolation between the two renders around it; nullopt if never.
std::optional<double> timeToTarget(std::vector<const SweepRow*> rows, double target) {
  std::sort(rows.begin(), rows.end(), [](const SweepRow* a, const SweepRow* b) { return a->timed.cpuSeconds < b->timed.cpuSeconds; });
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i]->error.rmse > target) continue;
    if (i == 0) return rows[0]->timed.cpuSeconds;
    const double r0 = std::log(rows[i - 1]->error.rmse), r1 = std::log(rows[i]->error.rmse);
    const double t0 = std::log(std::max(rows[i - 1]->timed.cpuSeconds, 1e-6)), t1 = std::log(std::max(rows[i]->timed.cpuSeconds, 1e-6));
    const double f = r0 != r1 ? (std::log(target) - r0) / (r1 - r0) : 1.0;
    return std::exp(t0 + std::clamp(f, 0.0, 1.0) * (t1 - t0));
  }
  return std::nullopt;
}

}  // namespace

SweepResult runSweep(SweepSpec& a) {
  const RenderMethod& method = findRenderMethod(a.method);
  if (method.properties.family != MethodFamily::Ray)
    throw InputError("sweep compares ray-tracing integrators; method " + a.method + " is " +
                     std::string(toString(method.properties.family)));
  const bool holds = holdsResults();  // under mpirun, rank 0's: the others render and no more
  if (par::ProcessGroup::get().ranks() > 1 && !runsAcrossRanks(method))
    throw InputError("method " + a.method + " does not run across processes (methods that do: " + methodsAcrossRanks() + ")");
  const bool photonmap = std::find(a.integrators.begin(), a.integrators.end(), "photonmap") != a.integrators.end();
  if (a.vary != "spp" && !photonmap)
    throw InputError("--vary " + a.vary + " varies a photon-map setting; add photonmap to --integrator or vary spp");
  const scene::EffectOverrides overrides = scene::parseEffectOverrides(a.effects);
  scene::Scene scene = loadScene(a.scene, a.lighting);
  const std::string lighting = applyLighting(scene, a.lighting);
  if (holds) std::fprintf(stderr, "%s\n", lighting.c_str());
  const scene::Camera camera = scene::selectCamera(scene, a.camera, float(a.width) / float(a.height));
  const scene::RenderPlan plan = scene::applyOverrides(scene::analyzeEffects(scene, &camera), overrides);
  if (a.values.empty()) a.values = defaultValues(a.vary, scene);
  // Each value must make sense for the setting it sets, checked before any cast.
  const VariedRange range = variedRange(a.vary);
  for (double v : a.values)
    if (!std::isfinite(v) || (range.leastAllowed ? v < range.least : !(v > range.least)) || v > range.most ||
        (range.integral && v != std::floor(v)))
      throw InputError("--values: " + formatValue(v) + " is not a valid " + a.vary + " (" +
                       (range.integral ? "an integer " : "a number ") + "in " + (range.leastAllowed ? "[" : "(") +
                       formatValue(range.least) + ", " + formatValue(range.most) + "])");
  const Context ctx{a, RenderInput{scene, camera, plan, a.width, a.height}};
  if (!a.images.empty() && holds) std::filesystem::create_directories(a.images);

  // The reference: reused when a render with exactly these settings is on disk.
  ReferenceSettings referenceSettings{a.scene, a.camera, a.effects, a.lighting, a.referenceSpp, a.referenceDepth, a.seed,
                                      a.referenceDir, a.noCache, a.method, everyRank(a.threads), a.schedule};
  Reference ref = pathReference(referenceSettings, ctx.input);
  const image::Image& reference = ref.image;

  // The caustic region: where the caustic map carries a good share of the reference's light.
  std::vector<bool> causticMask;
  if (photonmap && plan.on(scene::Effect::Caustics)) {
    RenderSettings view = baseSettings(a, "photonmap", 1, a.seed, a.maxDepth);
    view.ray.view = "caustic-map";
    const image::Image caustic = render(ctx, view).image;
    if (holds) causticMask.resize(caustic.pixels.size());
    for (std::size_t i = 0; i < caustic.pixels.size() && holds; ++i) {
      const double c = rt::luminance(caustic.pixels[i]), r = rt::luminance(reference.pixels[i]);
      causticMask[i] = c > 0.0 && c >= kCausticShare * r;
    }
  }

  // The series.
  std::vector<SweepRow> rows;
  std::size_t total = 0;
  // The path tracer's series: --path-spp when given, else --values when spp is varied.
  const std::vector<double> pathValues = (a.vary == "spp" && !a.pathSppGiven)
                                             ? a.values
                                             : std::vector<double>(a.pathSpp.begin(), a.pathSpp.end());
  for (const std::string& i : a.integrators) total += i == "photonmap" ? a.values.size() : pathValues.size();
  for (const std::string& integrator : a.integrators) {
    const bool photonSeries = integrator == "photonmap";
    const std::string setting = photonSeries ? a.vary : "spp";
    const std::vector<double>& values = photonSeries ? a.values : pathValues;
    for (double v : values) {
      RenderSettings s = baseSettings(a, integrator, a.spp, a.seed, a.maxDepth);
      if (integrator == "photonmap") applyVaried(a.vary, v, s);
      else s.ray.spp = int(v);
      SweepRow row{integrator, setting, v, render(ctx, s), {}};
      if (!holds) continue;
      row.error = imageError(row.timed.image, reference, causticMask);
      std::fprintf(stderr, "[%zu/%zu] %s %s %s: %.2f CPU s, RMSE %.5f\n", rows.size() + 1, total, integrator.c_str(),
                   setting.c_str(), formatValue(v).c_str(), row.timed.cpuSeconds, row.error.rmse);
      if (!a.images.empty()) {
        const std::string stem = (std::filesystem::path(a.images) / (integrator + "_" + setting + "_" + formatValue(v))).string();
        image::writeImage(stem + ".png", row.timed.image);
        image::writeImage(stem + "_diff8.png", differenceImage(row.timed.image, reference));
      }
      row.timed.image = {};  // keep the figures, not the pixels
      rows.push_back(std::move(row));
    }
  }
  if (!holds) return {};
  if (!a.images.empty()) image::writeImage((std::filesystem::path(a.images) / "reference.png").string(), reference);

  // The target RMSE: given, or the lowest RMSE every integrator reaches.
  double target = a.targetRmse;
  if (!(target > 0.0))
    for (const std::string& integrator : a.integrators) {
      double best = 1e300;
      for (const SweepRow& r : rows)
        if (r.integrator == integrator) best = std::min(best, r.error.rmse);
      target = std::max(target, best);
    }

  SweepResult result;
  result.lighting = lighting;
  result.causticPixels = rows.empty() ? std::size_t(0) : rows.front().error.maskedPixels;
  for (const std::string& integrator : a.integrators) {
    std::vector<const SweepRow*> mine;
    for (const SweepRow& r : rows)
      if (r.integrator == integrator) mine.push_back(&r);
    result.cpuSecondsToTarget.emplace_back(integrator, timeToTarget(mine, target));
  }
  result.rows = std::move(rows);
  result.reference = ref;
  result.targetRmse = target;
  return result;
}

}  // namespace pr::cli
