// `parrender sweep SCENE --vary photons|gather|spp|k|radius [--values LIST] --integrator LIST`:
// what accuracy costs in time. Renders a series of images, the photon-map integrator over the
// varied setting and the path tracer over its samples per pixel, compares each with a
// reference (a long path-traced render, cached on disk with its settings: sweep/reference_cache.h)
// and prints, and writes as CSV and JSON, one row per render: setting, CPU and wall seconds,
// RMSE, relative MSE, maximum error and the RMSE inside the caustic region; then the CPU time
// each integrator needs to reach a target RMSE, interpolated on its curve.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common/image/image_io.h"
#include "common/parallel/run_options.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "raytrace/integrators/sampling.h"
#include "tools/commands.h"
#include "tools/integrators.h"
#include "tools/lighting.h"
#include "tools/render_methods.h"
#include "tools/sweep/image_error.h"
#include "tools/sweep/path_reference.h"
#include "tools/timed_render.h"

namespace pr::cli {

namespace {

// A pixel is in the caustic region when the caustic map gives at least this share of the
// reference's radiance there: the pixels whose light the caustic map carries.
constexpr double kCausticShare = 0.25;

struct SweepArgs {
  std::string scene;
  std::string method = "image-space";
  int width = 256, height = 256;
  std::string camera;
  int threads = 1;
  std::string vary = "photons";
  std::vector<double> values;
  std::vector<std::string> integrators = {"photonmap", "path"};
  std::vector<int> pathSpp = {1, 4, 16, 64, 256};
  int spp = 4;
  int maxDepth = 8;
  std::uint64_t seed = 1;
  int referenceSpp = 1024;
  int referenceDepth = 16;
  bool pathSppGiven = false;
  std::string referenceDir;
  bool noCache = false;
  double targetRmse = 0.0;
  std::string csv, json, images, effects;
  pm::PhotonMapSettings photonmap;
  par::ScheduleOptions schedule;
  LightingOptions lighting;
};

struct Timed {
  image::Image image;
  double cpuSeconds = 0.0, wallSeconds = 0.0;
};

struct Context {
  const SweepArgs& args;
  RenderInput input;
};

// One timed render of the series: a fresh runtime, CPU time of the whole process (every PE).
Timed render(const Context& c, const RenderSettings& settings) {
  TimedRender t = timedRender(findRenderMethod(c.args.method), c.input, settings, c.args.threads, c.args.schedule);
  return Timed{std::move(t.outcome.image), t.cpuSeconds, t.wallSeconds};
}

RenderSettings baseSettings(const SweepArgs& a, const std::string& integrator, int spp, std::uint64_t seed, int depth) {
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
  }
}

std::vector<double> defaultValues(const std::string& vary, const scene::Scene& scene) {
  if (vary == "photons") return {25000, 50000, 100000, 200000, 400000};
  if (vary == "gather") return {32, 64, 128, 256, 512};
  if (vary == "spp") return {1, 2, 4, 8, 16};
  if (vary == "k") return {25, 50, 100, 200};
  const float diagonal = glm::length(scene.bounds.extent());
  return {0.02 * diagonal, 0.05 * diagonal, 0.1 * diagonal};
}

std::string format(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

struct Row {
  std::string integrator, setting;
  double value = 0.0;
  Timed timed;
  ImageError error;
};

// The CPU seconds at which an integrator's curve (rows by increasing cost) first reaches the
// target RMSE, by log-log interpolation between the two renders around it; nullopt if never.
std::optional<double> timeToTarget(std::vector<const Row*> rows, double target) {
  std::sort(rows.begin(), rows.end(), [](const Row* a, const Row* b) { return a->timed.cpuSeconds < b->timed.cpuSeconds; });
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

void run(SweepArgs& a) {
  const RenderMethod& method = findRenderMethod(a.method);
  if (method.properties.family != MethodFamily::Ray)
    throw InputError("sweep compares ray-tracing integrators; method " + a.method + " is " +
                     std::string(toString(method.properties.family)));
  const bool photonmap = std::find(a.integrators.begin(), a.integrators.end(), "photonmap") != a.integrators.end();
  if (a.vary != "spp" && !photonmap)
    throw InputError("--vary " + a.vary + " varies a photon-map setting; add photonmap to --integrator or vary spp");
  const scene::EffectOverrides overrides = scene::parseEffectOverrides(a.effects);
  scene::Scene scene = loadScene(a.scene, a.lighting);
  std::fprintf(stderr, "%s\n", applyLighting(scene, a.lighting).c_str());
  const scene::Camera camera = scene::selectCamera(scene, a.camera, float(a.width) / float(a.height));
  const scene::RenderPlan plan = scene::applyOverrides(scene::analyzeEffects(scene, &camera), overrides);
  if (a.values.empty()) a.values = defaultValues(a.vary, scene);
  // Each value must make sense for the setting it sets, checked before any cast.
  const double most = a.vary == "photons" ? 1e8 : a.vary == "gather" ? 65536.0 : a.vary == "spp" ? double(rt::kMaxSpp)
                    : a.vary == "k" ? 10000.0 : 1e30;
  const bool integral = a.vary != "radius";
  for (double v : a.values)
    if (!(v > 0.0) || !std::isfinite(v) || v > most || (integral && v != std::floor(v)))
      throw InputError("--values: " + format(v) + " is not a valid " + a.vary + " (" + (integral ? "an integer " : "a number ") +
                       "in (0, " + format(most) + "])");
  const Context ctx{a, RenderInput{scene, camera, plan, a.width, a.height}};
  if (!a.images.empty()) std::filesystem::create_directories(a.images);

  // The reference: reused when a render with exactly these settings is on disk.
  ReferenceSettings referenceSettings{a.scene, a.camera, a.effects, a.lighting, a.referenceSpp, a.referenceDepth, a.seed,
                                      a.referenceDir, a.noCache, a.method, a.threads, a.schedule};
  const Reference ref = pathReference(referenceSettings, ctx.input);
  const image::Image& reference = ref.image;
  const bool cached = ref.cached;
  const double referenceCpu = ref.cpuSeconds;

  // The caustic region: where the caustic map carries a good share of the reference's light.
  std::vector<bool> causticMask;
  if (photonmap && plan.on(scene::Effect::Caustics)) {
    RenderSettings view = baseSettings(a, "photonmap", 1, a.seed, a.maxDepth);
    view.ray.view = "caustic-map";
    const image::Image caustic = render(ctx, view).image;
    causticMask.resize(caustic.pixels.size());
    for (std::size_t i = 0; i < caustic.pixels.size(); ++i) {
      const double c = rt::luminance(caustic.pixels[i]), r = rt::luminance(reference.pixels[i]);
      causticMask[i] = c > 0.0 && c >= kCausticShare * r;
    }
  }

  // The series.
  std::vector<Row> rows;
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
      Row row{integrator, setting, v, render(ctx, s), {}};
      row.error = imageError(row.timed.image, reference, causticMask);
      std::fprintf(stderr, "[%zu/%zu] %s %s %s: %.2f CPU s, RMSE %.5f\n", rows.size() + 1, total, integrator.c_str(),
                   setting.c_str(), format(v).c_str(), row.timed.cpuSeconds, row.error.rmse);
      if (!a.images.empty()) {
        const std::string stem = (std::filesystem::path(a.images) / (integrator + "_" + setting + "_" + format(v))).string();
        image::writeImage(stem + ".png", row.timed.image);
        image::writeImage(stem + "_diff8.png", differenceImage(row.timed.image, reference));
      }
      row.timed.image = {};  // keep the figures, not the pixels
      rows.push_back(std::move(row));
    }
  }
  if (!a.images.empty()) image::writeImage((std::filesystem::path(a.images) / "reference.png").string(), reference);

  // The target RMSE: given, or the lowest RMSE every integrator reaches.
  double target = a.targetRmse;
  if (!(target > 0.0))
    for (const std::string& integrator : a.integrators) {
      double best = 1e300;
      for (const Row& r : rows)
        if (r.integrator == integrator) best = std::min(best, r.error.rmse);
      target = std::max(target, best);
    }

  std::printf("sweep of %s, %dx%d, method %s, P %d; reference: path tracing, %d spp%s\n", a.scene.c_str(), a.width,
              a.height, a.method.c_str(), a.threads, a.referenceSpp, cached ? " (cached)" : "");
  std::printf("%-10s %-8s %10s %9s %9s %10s %10s %9s %12s\n", "integrator", "setting", "value", "cpu_s", "wall_s", "rmse",
              "rel_mse", "max_err", "caustic_rmse");
  for (const Row& r : rows)
    std::printf("%-10s %-8s %10s %9.3f %9.3f %10.5f %10.5f %9.4f %12.5f\n", r.integrator.c_str(), r.setting.c_str(),
                format(r.value).c_str(), r.timed.cpuSeconds, r.timed.wallSeconds, r.error.rmse, r.error.relativeMse,
                r.error.maxError, r.error.maskedRmse);
  std::printf("caustic region: %zu pixels (caustic map >= %.0f%% of the reference's radiance)\n",
              rows.empty() ? std::size_t(0) : rows.front().error.maskedPixels, 100.0 * kCausticShare);
  nlohmann::json toTarget = nlohmann::json::object();
  std::printf("CPU time to reach RMSE %.5f:", target);
  for (const std::string& integrator : a.integrators) {
    std::vector<const Row*> mine;
    for (const Row& r : rows)
      if (r.integrator == integrator) mine.push_back(&r);
    const std::optional<double> t = timeToTarget(mine, target);
    std::printf(" %s %s", integrator.c_str(), t ? (format(*t) + " s").c_str() : "not reached");
    toTarget[integrator] = t ? nlohmann::json(*t) : nlohmann::json(nullptr);
  }
  std::printf("\n");

  if (!a.csv.empty()) {
    std::ostringstream out;
    out << "integrator,setting,value,cpu_seconds,wall_seconds,rmse,relative_mse,max_error,caustic_rmse\n";
    for (const Row& r : rows)
      out << r.integrator << "," << r.setting << "," << format(r.value) << "," << format(r.timed.cpuSeconds) << ","
          << format(r.timed.wallSeconds) << "," << format(r.error.rmse) << "," << format(r.error.relativeMse) << ","
          << format(r.error.maxError) << "," << format(r.error.maskedRmse) << "\n";
    writeFileAtomically(a.csv, out.str(), "CSV file");
  }
  if (!a.json.empty()) {
    nlohmann::json j = {{"scene", a.scene}, {"method", a.method}, {"threads", a.threads}, {"width", a.width},
                        {"height", a.height}, {"vary", a.vary}, {"targetRmse", target}, {"cpuSecondsToTarget", toTarget},
                        {"reference", {{"integrator", "path"}, {"spp", a.referenceSpp}, {"maxDepth", a.referenceDepth},
                                       {"cached", bool(cached)}, {"cpuSeconds", referenceCpu}}},
                        {"causticPixels", rows.empty() ? std::size_t(0) : rows.front().error.maskedPixels}};
    nlohmann::json list = nlohmann::json::array();
    for (const Row& r : rows)
      list.push_back({{"integrator", r.integrator}, {"setting", r.setting}, {"value", r.value},
                      {"cpuSeconds", r.timed.cpuSeconds}, {"wallSeconds", r.timed.wallSeconds}, {"rmse", r.error.rmse},
                      {"relativeMse", r.error.relativeMse}, {"maxError", r.error.maxError},
                      {"causticRmse", r.error.maskedRmse}});
    j["rows"] = list;
    writeFileAtomically(a.json, j.dump(2) + "\n", "JSON file");
  }
}

}  // namespace

void addSweepCommand(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand("sweep", "accuracy against time: render a series, compare each image with a path-traced reference");
  cmd->add_option("scene", a->scene, "glTF 2.0 scene (.gltf or .glb)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--vary", a->vary, "the photon map's setting to vary: photons | gather | spp | k | radius")
      ->check(CLI::IsMember({"photons", "gather", "spp", "k", "radius"}))
      ->capture_default_str();
  cmd->add_option("--values", a->values, "the varied setting's values, comma-separated (default: a series per setting)")->delimiter(',');
  cmd->add_option("--integrator", a->integrators, "integrators to compare, comma-separated (path is swept over --path-spp unless --vary spp)")
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return integrators().problem(v); }, "INTEGRATOR"))
      ->capture_default_str();
  CLI::Option* pathSpp = cmd->add_option("--path-spp", a->pathSpp, "the path tracer's samples per pixel, comma-separated (default: --values with --vary spp)")
      ->delimiter(',')->check(CLI::Range(1, rt::kMaxSpp))->capture_default_str();
  cmd->add_option("-m,--method", a->method, "ray-tracing method (the image does not depend on it)")
      ->check(CLI::Validator([](std::string& v) { return renderMethods().problem(v); }, "METHOD"))
      ->capture_default_str();
  cmd->add_option("--width", a->width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--height", a->height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--camera", a->camera, "camera: index, name, or 'auto'");
  cmd->add_option("--threads", a->threads, "P, the number of PEs of every render")->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--spp", a->spp, "photonmap: samples per pixel (unless varied)")->check(CLI::Range(1, rt::kMaxSpp))->capture_default_str();
  cmd->add_option("--max-depth", a->maxDepth, "surface interactions per path")->check(CLI::Range(1, rt::kMaxDepthLimit))->capture_default_str();
  cmd->add_option("--seed", a->seed, "random seed of the series")->capture_default_str();
  cmd->add_option("--reference-spp", a->referenceSpp, "the reference's samples per pixel")->check(CLI::Range(1, rt::kMaxSpp))->capture_default_str();
  cmd->add_option("--reference-depth", a->referenceDepth, "the reference's path depth")->check(CLI::Range(1, rt::kMaxDepthLimit))->capture_default_str();
  cmd->add_option("--reference-dir", a->referenceDir, "where references are cached (default $XDG_CACHE_HOME/parrender/references)");
  cmd->add_flag("--no-cache", a->noCache, "render the reference afresh and do not store it");
  cmd->add_option("--target-rmse", a->targetRmse, "the RMSE to report the CPU time to reach (default: the lowest every integrator reaches)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--csv", a->csv, "write the rows as CSV");
  cmd->add_option("--json", a->json, "write the rows and the times to target as JSON");
  cmd->add_option("--images", a->images, "folder for every render (PNG), its x8 difference from the reference and the reference");
  cmd->add_option("--effects", a->effects, "force effects on or off, as for render");
  pm::PhotonMapSettings& p = a->photonmap;
  cmd->add_option("--photons", p.globalPhotons, "photonmap: global photons (unless varied)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}))->capture_default_str();
  cmd->add_option("--caustic-photons", p.causticPhotons, "photonmap: caustic photons (scaled with --photons when that is varied)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}))->capture_default_str();
  cmd->add_option("--gather", p.gatherRays, "photonmap: final-gather rays per record")->check(CLI::Range(1, 65536))->capture_default_str();
  cmd->add_option("--k", p.globalK, "photonmap: photons per global-map estimate")->check(CLI::Range(1, 10000))->capture_default_str();
  cmd->add_option("--radius", p.globalRadius, "photonmap: global-map radius (0 = automatic)")->check(CLI::NonNegativeNumber)->capture_default_str();
  par::addScheduleOptions(*cmd, a->schedule);
  addLightingOptions(*cmd, a->lighting);
  cmd->callback([a, pathSpp] {
    a->pathSppGiven = pathSpp->count() > 0;
    run(*a);
  });
}

}  // namespace pr::cli
