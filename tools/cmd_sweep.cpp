// `parrender sweep SCENE --vary photons|gather|spp|k|radius|cache-accuracy|irradiance-stride [--values LIST] --integrator LIST`:
// what accuracy costs in time. Renders a series of images, the photon-map integrator over the
// varied setting and the path tracer over its samples per pixel, compares each with a
// reference (a long path-traced render, cached on disk with its settings: sweep/reference_cache.h)
// and prints, and writes as CSV and JSON, one row per render: setting, CPU and wall seconds,
// RMSE, relative MSE, maximum error and the RMSE inside the caustic region; then the CPU time
// each integrator needs to reach a target RMSE, interpolated on its curve. The series itself
// is sweep/sweep.h; this file is its command line and its table and files.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common/image/codec_loader.h"
#include "common/parallel/run_options.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "tools/commands.h"
#include "tools/integrators.h"
#include "tools/lighting.h"
#include "tools/render_methods.h"
#include "tools/sweep/sweep.h"

namespace pr::cli {

namespace {

struct SweepArgs : SweepSpec {
  std::string csv, json;
};

void run(SweepArgs& a) {
  // Under mpirun, --threads is each rank's PEs; rank 0 prints and writes.
  const bool writes = holdsResults();
  if (writes) image::imageCodec();  // the cached reference and the images; opened before the first timed render
  const SweepResult result = runSweep(a);
  if (!writes) return;
  const std::vector<SweepRow>& rows = result.rows;
  const double target = result.targetRmse;
  const bool cached = result.reference.cached;
  const double referenceCpu = result.reference.cpuSeconds;
  const Placement where = everyRank(a.threads);
  std::printf("sweep of %s, %dx%d, method %s, P %d%s; reference: path tracing, %d spp%s\n", a.scene.c_str(), a.width,
              a.height, a.method.c_str(), where.pes, where.acrossRanks().c_str(), a.referenceSpp, cached ? " (cached)" : "");
  std::printf("%-10s %-8s %10s %9s %9s %10s %10s %9s %12s\n", "integrator", "setting", "value", "cpu_s", "wall_s", "rmse",
              "rel_mse", "max_err", "caustic_rmse");
  for (const SweepRow& r : rows)
    std::printf("%-10s %-8s %10s %9.3f %9.3f %10.5f %10.5f %9.4f %12.5f\n", r.integrator.c_str(), r.setting.c_str(),
                formatValue(r.value).c_str(), r.timed.cpuSeconds, r.timed.wallSeconds, r.error.rmse, r.error.relativeMse,
                r.error.maxError, r.error.maskedRmse);
  std::printf("caustic region: %zu pixels (caustic map >= %.0f%% of the reference's radiance)\n",
              rows.empty() ? std::size_t(0) : rows.front().error.maskedPixels, 100.0 * kCausticShare);
  nlohmann::json toTarget = nlohmann::json::object();
  std::printf("CPU time to reach RMSE %.5f:", target);
  for (const auto& [integrator, t] : result.cpuSecondsToTarget) {
    std::printf(" %s %s", integrator.c_str(), t ? (formatValue(*t) + " s").c_str() : "not reached");
    toTarget[integrator] = t ? nlohmann::json(*t) : nlohmann::json(nullptr);
  }
  std::printf("\n");

  if (!a.csv.empty()) {
    std::ostringstream out;
    out << "integrator,setting,value,cpu_seconds,wall_seconds,rmse,relative_mse,max_error,caustic_rmse\n";
    for (const SweepRow& r : rows)
      out << r.integrator << "," << r.setting << "," << formatValue(r.value) << "," << formatValue(r.timed.cpuSeconds) << ","
          << formatValue(r.timed.wallSeconds) << "," << formatValue(r.error.rmse) << "," << formatValue(r.error.relativeMse) << ","
          << formatValue(r.error.maxError) << "," << formatValue(r.error.maskedRmse) << "\n";
    writeFileAtomically(a.csv, out.str(), "CSV file");
  }
  if (!a.json.empty()) {
    nlohmann::json j = {{"scene", a.scene}, {"method", a.method}, {"threads", a.threads}, {"pes", where.pes}, {"width", a.width},
                        {"height", a.height}, {"vary", a.vary}, {"targetRmse", target}, {"cpuSecondsToTarget", toTarget},
                        {"reference", {{"integrator", "path"}, {"spp", a.referenceSpp}, {"maxDepth", a.referenceDepth},
                                       {"cached", bool(cached)}, {"cpuSeconds", referenceCpu}}},
                        {"causticPixels", rows.empty() ? std::size_t(0) : rows.front().error.maskedPixels}};
    nlohmann::json list = nlohmann::json::array();
    for (const SweepRow& r : rows)
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
  cmd->add_option("--vary", a->vary,
                  "the photon map's setting to vary: photons | gather | spp | k | radius | cache-accuracy | irradiance-stride")
      ->check(CLI::IsMember({"photons", "gather", "spp", "k", "radius", "cache-accuracy", "irradiance-stride"}))
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
  cmd->add_option("--threads", a->threads, "P, the number of PEs of every render (under mpirun: PEs per rank, P = ranks x threads)")->check(CLI::Range(1, 4096))->capture_default_str();
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
  cmd->add_option("--cache-accuracy", p.cacheAccuracy, "photonmap: irradiance-cache accuracy a (smaller = more records)")
      ->check(CLI::Range(0.001f, 1.0f))->capture_default_str();
  cmd->add_option("--irradiance-stride", p.irradianceStride,
                  "photonmap: every n-th global photon carries a precomputed irradiance that gathers read (0 = none)")
      ->check(CLI::Range(0, 1024))->capture_default_str();
  par::addScheduleOptions(*cmd, a->schedule);
  addLightingOptions(*cmd, a->lighting);
  cmd->callback([a, pathSpp] {
    a->pathSppGiven = pathSpp->count() > 0;
    run(*a);
  });
}

}  // namespace pr::cli
