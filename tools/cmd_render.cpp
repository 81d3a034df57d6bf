// `parrender render SCENE -m METHOD -o out.png|out.exr ...`: loads a glTF scene, renders it with
// one method of the registry (tools/render_methods.h) on the parallel runtime with P PEs and a
// scheduling strategy, writes the image, the run record and the timeline when asked, and
// prints a summary read from the RunRecord through common/parallel/metrics.h.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include <CLI/CLI.hpp>

#include "common/image/codec_loader.h"
#include "common/image/image_io.h"
#include "common/parallel/metrics.h"
#include "common/parallel/process_group.h"
#include "common/parallel/run_options.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "tools/commands.h"
#include "tools/farm_render.h"
#include "tools/lighting.h"
#include "tools/render_methods.h"
#include "tools/timed_render.h"

namespace pr::cli {

namespace {

struct RenderArgs {
  std::string scene;
  std::string method = "image-space";
  std::string output;
  int width = 512, height = 512;
  std::string camera;
  int threads = 1;
  bool quiet = false;
  std::string effects;  // --effects NAME=on|off,...
  par::ScheduleOptions schedule;
  par::RunOutputOptions outputs;
  RenderSettings settings;
  FamilyOptions family;
  LightingOptions lighting;
  FarmArgs farm;
};

// A progress bar on stderr: appears once a render has run for a second, redrawn when the
// shown percentage changes; off when stderr is not a terminal or with --quiet.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled), start_(std::chrono::steady_clock::now()) {}
  ~ProgressBar() { finish(); }

  void update(int64_t done, int64_t total) {
    if (!enabled_ || total <= 0) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;  // another PE is drawing; skip rather than wait
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (elapsed < kDelaySeconds) return;
    const int percent = int(100 * done / total);
    if (percent == lastPercent_) return;
    lastPercent_ = percent;
    constexpr int kWidth = 40;
    const int filled = int(kWidth * done / total);
    std::fprintf(stderr, "\r[%.*s%*s] %3d%% %lld/%lld %.1fs", filled, "########################################",
                 kWidth - filled, "", percent, (long long)done, (long long)total, elapsed);
    std::fflush(stderr);
    drawn_ = true;
  }

  void finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  static constexpr double kDelaySeconds = 1.0;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  int lastPercent_ = -1;
  bool drawn_ = false;
};

std::string defaultOutput(const std::string& scene, const std::string& method) {
  return std::filesystem::path(scene).stem().string() + "_" + method + ".png";
}

// Under mpirun: the method must run across ranks (the others say so, exit 2).
void checkAcrossRanks(const RenderMethod& method, int ranks) {
  if (ranks == 1) return;
  if (!runsAcrossRanks(method))
    throw InputError("method " + method.name + " does not run across processes (launched as " + std::to_string(ranks) +
                     " ranks by mpirun; methods that do: " + methodsAcrossRanks() + "); run it without mpirun, with --threads P");
}

void run(RenderArgs& a) {
  const RenderMethod& method = findRenderMethod(a.method);
  checkFamilyOptions(method, a.family);
  // Under mpirun, --threads is each rank's: P = R x T PEs, and rank 0 writes and prints.
  par::ProcessGroup& group = par::ProcessGroup::get();
  reportFarmStatus(a.farm);
  checkFarm(a.farm, method, a.settings, group.ranks());
  checkAcrossRanks(method, group.ranks());
  const bool writes = holdsResults();
  const Placement where = everyRank(a.threads);
  const int pes = where.pes;
  checkRenderMemory(method, a.width, a.height, a.threads, samplesPerPixel(a.settings.ray));
  const scene::EffectOverrides overrides = scene::parseEffectOverrides(a.effects);
  if (a.output.empty()) a.output = defaultOutput(a.scene, a.method);
  const std::string ext = std::filesystem::path(a.output).extension().string();
  if (ext != ".png" && ext != ".exr")
    throw InputError("output " + a.output + ": unsupported extension '" + ext + "' (expected .png or .exr)");
  if (writes) image::preloadImageCodec();  // opened while the scene loads

  scene::Scene scene = loadScene(a.scene, a.lighting);
  // Loaded by now, or nearly: a missing codec fails before the render, and its loading never
  // runs beside the timed stages.
  if (writes) image::imageCodec();
  const std::string lighting = applyLighting(scene, a.lighting);
  const scene::Camera camera = scene::selectCamera(scene, a.camera, float(a.width) / float(a.height));
  const scene::RenderPlan plan = scene::applyOverrides(scene::analyzeEffects(scene, &camera), overrides);

  if (a.farm.enabled) {
    if (writes) warnWithoutRecovery();
    const par::RunRecord record =
        renderOnFarm(a.farm, FarmInput{scene, camera, plan, a.width, a.height, a.settings, a.schedule, a.threads}, a.output).record;
    if (!writes) return;
    par::writeRunOutputs(record, a.outputs);
    std::printf("method %s (%s) as a farm: a master and %d servers x %d PE%s, schedule %s among each server's PEs, %dx%d -> %s\n",
                a.method.c_str(), std::string(toString(method.properties.family)).c_str(), group.ranks() - 1, a.threads,
                a.threads == 1 ? "" : "s", a.schedule.schedule.c_str(), a.width, a.height, a.output.c_str());
    std::printf("%s\n", lighting.c_str());
    std::printf("effects:\n");
    for (scene::Effect e : scene::allEffects()) std::printf("  %s\n", plan.line(e).c_str());
    std::fputs(farmSummary(record).c_str(), stdout);
    return;
  }

  par::Runtime runtime(par::RuntimeOptions{pes, a.schedule.schedule, a.schedule.params, true,
                                           group.ranks() > 1 ? &group.transport() : nullptr});
  ProgressBar bar(writes && !a.quiet && isatty(STDERR_FILENO));
  const RenderRequest request{scene, camera, a.width, a.height, a.settings, plan, runtime,
                              [&bar](int64_t done, int64_t total) { bar.update(done, total); }};
  RenderOutcome outcome = method.make(method.name, request);
  bar.finish();
  if (!writes) return;

  image::writeImage(a.output, outcome.image);
  par::writeRunOutputs(runtime.record(), a.outputs);

  const par::RunSummary summary = par::summarize(runtime.record());
  const double wall = summary.wallSeconds;
  std::printf("method %s (%s), P %d%s, schedule %s, %dx%d -> %s\n", a.method.c_str(), std::string(toString(method.properties.family)).c_str(),
              pes, where.acrossRanks().c_str(), a.schedule.schedule.c_str(), a.width, a.height, a.output.c_str());
  std::printf("%s\n", lighting.c_str());
  std::printf("effects:\n");
  for (scene::Effect e : scene::allEffects()) std::printf("  %s\n", plan.line(e).c_str());
  if (!outcome.effects.empty()) std::printf("%s\n", outcome.effects.c_str());
  if (!outcome.details.empty()) std::printf("%s\n", outcome.details.c_str());
  std::printf("wall %.3f s", wall);
  if (outcome.rays > 0)
    std::printf(", rays %llu, %.2f Mrays/s", (unsigned long long)outcome.rays, wall > 0.0 ? double(outcome.rays) / wall * 1e-6 : 0.0);
  std::printf(", load imbalance %.3f, serial fraction %.3f, utilisation %.3f, messages %llu (%llu bytes), broadcast %.0f bytes "
              "to each other PE\n",
              summary.total.imbalance, summary.total.serialFraction, summary.total.utilisation, (unsigned long long)summary.total.messages,
              (unsigned long long)summary.total.bytes, summary.total.figure("broadcastBytesReceived").max);
  if (!summary.total.byKind.empty()) {
    std::printf("traffic by kind:");
    const char* separator = " ";
    for (const par::KindTraffic& k : summary.total.byKind) {
      std::printf("%s%s %llu (%llu bytes)", separator, k.kind.c_str(), (unsigned long long)k.messages,
                  (unsigned long long)k.bytes);
      separator = ", ";
    }
    if (summary.total.computeToComm >= 0.0)
      std::printf("; computation/communication %.1f", summary.total.computeToComm);
    std::printf("\n");
    // Across ranks: what of it crossed between the processes, the rest staying within one.
    if (group.ranks() > 1) {
      std::printf("between ranks:");
      separator = " ";
      for (const par::KindTraffic& k : summary.total.byKind) {
        std::printf("%s%s %llu (%llu bytes)", separator, k.kind.c_str(), (unsigned long long)k.betweenRankMessages,
                    (unsigned long long)k.betweenRankBytes);
        separator = ", ";
      }
      std::printf("; within ranks: the rest\n");
      // What one process would book as broadcasts to these PEs and each rank made itself.
      std::uint64_t copies = 0, bytes = 0;
      for (const par::StageRecord& s : runtime.record().stages)
        for (const par::PeStageRecord& pe : s.pes) {
          copies += pe.replicatedCopies;
          bytes += pe.replicatedBytes;
        }
      if (copies > 0)
        std::printf("replicated on the other ranks (loaded or built there, not sent): %llu copies (%llu bytes)\n",
                    (unsigned long long)copies, (unsigned long long)bytes);
    }
  }
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render a glTF scene with one method on P PEs; write the image and a summary");
  cmd->add_option("scene", args->scene, "glTF 2.0 scene (.gltf or .glb)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-m,--method", args->method, "render method (default image-space):\n" + describeRenderMethods())
      ->check(CLI::Validator([](std::string& v) { return renderMethods().problem(v); }, "METHOD"));
  cmd->add_option("-o,--output", args->output, "output image, .png or .exr (default <scene stem>_<method>.png)");
  cmd->add_option("--width", args->width, "image width in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--height", args->height, "image height in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--camera", args->camera, "camera: index, name, or 'auto' (default: the file's first)");
  cmd->add_option("--threads", args->threads, "P, the number of PEs (under mpirun: PEs per rank, P = ranks x threads)")->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_flag("--quiet", args->quiet, "no progress bar");
  std::string effectNames;
  for (scene::Effect e : scene::allEffects()) effectNames += (effectNames.empty() ? "" : ", ") + std::string(scene::toString(e));
  cmd->add_option("--effects", args->effects,
                  "force effects of the render plan on or off, e.g. caustics=off,indirect=on; names: " + effectNames +
                      " (ray tracers skip the work of effects that are off; rasterization reports the plan only)");
  par::addScheduleOptions(*cmd, args->schedule);
  par::addRunOutputOptions(*cmd, args->outputs);
  addLightingOptions(*cmd, args->lighting);
  addRayOptions(*cmd, args->settings, args->family);
  addRasterOptions(*cmd, args->settings, args->family);
  addFarmOptions(*cmd, args->farm,
                 "render as a farm under mpirun --enable-recovery: rank 0 hands out screen areas, the other ranks render "
                 "them with --threads PEs each; a server that dies or stops answering loses no job (image-space only)");
  addFarmRenderOptions(*cmd, args->farm);
  cmd->callback([args] { run(*args); });
}

}  // namespace pr::cli
