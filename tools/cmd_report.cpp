// `parrender report SCENE [SCENE...] -o DIR`: a self-contained report that classifies the
// methods the way the seed course does and shows the figures measured on each scene behind
// every claim (report/scene_report.h). DIR/index.html opens offline: its images, chart data
// and the plotting libraries (Vega-Lite, installed by tools/setup.sh under
// tools/report/node_modules) lie beside it. The report is built in a new folder beside DIR and
// renamed into place once complete, so an interrupted run never replaces an earlier report.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/image/codec_loader.h"
#include "common/parallel/process_group.h"
#include "common/parallel/simulator.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/interrupt.h"
#include "tools/commands.h"
#include "tools/compare/comparison.h"
#include "tools/report/classification.h"
#include "tools/report/html.h"
#include "tools/report/scene_report.h"

#ifndef PARRENDER_REPORT_SCRIPTS
#define PARRENDER_REPORT_SCRIPTS ""
#endif

namespace pr::cli {

namespace {

// Written into every report: the mark that lets a later run replace the folder.
constexpr const char* kReportMarker = ".parrender-report";

struct ReportArgs {
  std::vector<std::string> scenes;
  std::string output = "report";
  report::ReportSpec spec;
};

// Where the plotting libraries are: $PARRENDER_REPORT_SCRIPTS, else the folder setup.sh fills.
std::filesystem::path scriptsDir() {
  if (const char* env = std::getenv("PARRENDER_REPORT_SCRIPTS"); env && *env) return env;
  return PARRENDER_REPORT_SCRIPTS;
}

// The three libraries and their licences into dir/lib.
void copyScripts(const std::filesystem::path& dir) {
  const std::filesystem::path from = scriptsDir();
  std::filesystem::create_directories(dir / "lib");
  for (const char* package : {"vega", "vega-lite", "vega-embed"}) {
    const std::filesystem::path script = from / package / "build" / (std::string(package) + ".min.js");
    if (!std::filesystem::exists(script))
      throw InputError("report: the plotting library " + script.string() +
                       " is missing; run tools/setup.sh (it installs vega, vega-lite and vega-embed with npm), "
                       "or point PARRENDER_REPORT_SCRIPTS at a node_modules folder holding them");
    std::filesystem::copy_file(script, dir / "lib" / script.filename(), std::filesystem::copy_options::overwrite_existing);
    for (const char* licence : {"LICENSE", "LICENSE.txt"})
      if (std::filesystem::exists(from / package / licence))
        std::filesystem::copy_file(from / package / licence, dir / "lib" / (std::string(package) + "-LICENSE.txt"),
                                   std::filesystem::copy_options::overwrite_existing);
  }
}

std::string methodsIntro(const report::ReportSpec& spec) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& s : spec.schedules) {
    const report::ScheduleClass k = report::classifySchedule(s);
    rows.push_back({s, k.model, k.taskManagement});
  }
  return "<p>Every method is classified after the SIGGRAPH 2000 course <i>Practical Parallel Processing for Realistic "
         "Rendering</i>: by task subdivision (screen space or object space; for polygons where the sort happens, "
         "after Molnar et al.; for ray tracing image space, object space or object partitioning), by computational model "
         "and task management (the schedule), and by data management; each class beside the figure that defines it, "
         "measured on the scene. Every figure comes from the run records of timed renders on this machine (" +
         std::to_string(std::thread::hardware_concurrency()) + " cores); predictions beyond are the simulator's.</p>" +
         report::table({"schedule", "computational model", "task management"}, rows, "text");
}

// The report's files but the scenes' sections, into dir (made).
void prepare(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  copyScripts(dir);
  writeFileAtomically(dir / "page.js", report::pageScript(), "report script");
  writeFileAtomically(dir / kReportMarker, "a report written by parrender report; the next report into this folder replaces it\n",
                      "report marker");
}

// Every scene's renders (every rank takes part) and section; index.html written by rank 0.
// Returns the renders whose image differs from their family's (rank 0's count).
int build(const ReportArgs& a, const std::filesystem::path& dir) {
  int mismatches = 0;
  std::string body = "<h1>parrender: parallel rendering methods compared</h1>\n" + methodsIntro(a.spec);
  body += "<p>Scenes:";
  for (const std::string& s : a.scenes) {
    const std::string stem = std::filesystem::path(s).stem().string();
    body += " <a href=\"#" + report::escape(report::urlPath(stem)) + "\">" + report::escape(stem) + "</a>";
  }
  body += "</p>\n";
  for (const std::string& s : a.scenes) {
    const std::string stem = std::filesystem::path(s).stem().string();
    const report::SceneSection section = report::sceneReport(s, a.spec, dir / stem, stem);
    body += "<a id=\"" + report::escape(stem) + "\"></a>" + section.html;
    mismatches += section.mismatches;
  }
  par::ProcessGroup::get().onRank0Alone("rank 0 writing the report's page", [&] {
    writeFileAtomically(dir / "index.html", report::page("parrender report", body), "report page");
    return par::Bytes();
  });
  return mismatches;
}

void run(ReportArgs& a) {
  for (const std::string& m : a.spec.methods) report::classifyMethod(m);
  for (const std::string& s : a.spec.schedules) report::classifySchedule(s);
  par::networkByName(a.spec.network);
  // Under mpirun, --threads is each rank's PEs (default one); P = 1 runs on rank 0 alone, and
  // rank 0 alone reads and writes the report's folder while the other ranks wait.
  par::ProcessGroup& group = par::ProcessGroup::get();
  checkFarm(a.spec.farm, findRenderMethod("image-space"), a.spec.settings, group.ranks());
  if (a.spec.threads.empty()) a.spec.threads = defaultThreadCounts();
  if (group.ranks() == 1 && std::find(a.spec.threads.begin(), a.spec.threads.end(), 1) == a.spec.threads.end())
    throw InputError("--threads must include 1: speed-up and efficiency are measured against P = 1");
  for (const std::string& scene : a.scenes) {
    const std::string stem = std::filesystem::path(scene).stem().string();
    if (stem == "lib" || stem == "index.html" || stem == "page.js" || stem == kReportMarker || stem.empty() || stem[0] == '.')
      throw InputError("scene " + scene + ": its name '" + stem + "' is reserved in the report's folder; copy or link it under another name");
  }
  for (std::size_t i = 0; i < a.scenes.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (std::filesystem::path(a.scenes[i]).stem() == std::filesystem::path(a.scenes[j]).stem())
        throw InputError("scenes " + a.scenes[j] + " and " + a.scenes[i] + " share the name of their report folder");
  std::filesystem::path out, fresh, old;
  // The new report's folder while it fills: an interrupt removes it (interrupt.h).
  struct FolderSlot {
    int slot = -1;
    ~FolderSlot() { unregisterTemporary(slot); }
  } freshSlot;
  group.onRank0Alone("rank 0's preparation of the report's folder", [&] {
    out = std::filesystem::absolute(a.output).lexically_normal();
    if (!out.has_filename()) out = out.parent_path();  // "report/" or "."
    if (!out.has_filename() || out == out.root_path())
      throw InputError("report: " + a.output + " cannot be a report's folder (it must name a folder below another)");
    const std::filesystem::path parent = out.parent_path();
    std::error_code made;
    std::filesystem::create_directories(parent, made);
    if (!std::filesystem::is_directory(parent))
      throw InputError("report: cannot make the folder " + parent.string() + (made ? " (" + made.message() + ")" : std::string()));
    if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
      throw InputError("report: " + out.string() + " exists and is not a folder");
    // Only a report (or an empty folder) is replaced: never a folder of someone's files.
    if (std::filesystem::is_directory(out) && !std::filesystem::is_empty(out) && !std::filesystem::exists(out / kReportMarker))
      throw InputError("report: " + out.string() + " holds files that are not a parrender report (no " +
                       std::string(kReportMarker) + " inside); choose another folder");
    const std::string pid = std::to_string(getpid());
    fresh = parent / ("." + out.filename().string() + ".new-" + pid);
    old = parent / ("." + out.filename().string() + ".old-" + pid);
    std::filesystem::remove_all(fresh);
    std::filesystem::remove_all(old);
    freshSlot.slot = registerTemporaryFolder(fresh.c_str());
    try {
      image::imageCodec();  // opened before the first timed render, never beside it
      prepare(fresh);
    } catch (...) {
      std::error_code ignored;
      std::filesystem::remove_all(fresh, ignored);
      throw;
    }
    return par::Bytes();
  });
  const bool writes = holdsResults();
  int mismatches = 0;  // rank 0's count
  try {
    mismatches = build(a, fresh);
    // The earlier report steps aside only once the new one is whole, and comes back if the
    // new one cannot take its place.
    group.onRank0Alone("rank 0 putting the report in place", [&] {
      const bool earlier = std::filesystem::exists(out);
      if (earlier) std::filesystem::rename(out, old);
      try {
        std::filesystem::rename(fresh, out);
      } catch (...) {
        if (earlier) std::filesystem::rename(old, out);
        throw;
      }
      return par::Bytes();
    });
  } catch (...) {
    std::error_code ignored;
    if (writes) std::filesystem::remove_all(fresh, ignored);
    throw;
  }
  if (!writes) return;
  std::error_code ignored;
  std::filesystem::remove_all(old, ignored);
  std::printf("report: %s\n", (out / "index.html").string().c_str());
  // As compare does: the report is written (its verdict leaves them out), and the run fails.
  if (mismatches > 0)
    throw std::runtime_error(std::to_string(mismatches) +
                             " render(s) differ from their family's image (IMAGE MISMATCH above; the report marks them)");
}

}  // namespace

void addReportCommand(CLI::App& app) {
  auto a = std::make_shared<ReportArgs>();
  report::ReportSpec& s = a->spec;
  for (std::string_view m : renderMethods().names()) s.methods.emplace_back(m);
  s.schedules = {"demand", "balanced", "preferred-bias"};
  CLI::App* cmd = app.add_subcommand("report", "a self-contained HTML report classifying the methods, with the figures measured on each scene");
  cmd->add_option("scenes", a->scenes, "glTF 2.0 scenes (.gltf or .glb)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a->output, "the report's folder (index.html inside; replaced whole when done)")->capture_default_str();
  cmd->add_option("--methods", s.methods, "render methods, comma-separated (default: all)")
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return renderMethods().problem(v); }, "METHOD"));
  cmd->add_option("--threads", s.threads, "values of P, comma-separated, with 1 (default: 1, 2, 4, ... and this machine's cores); under mpirun, "
                "PEs per rank (P = ranks x each, default 1), and P = 1 on rank 0 alone")
      ->delimiter(',')
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--schedules", s.schedules, "schedules, comma-separated")
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return par::schedules().problem(v); }, "SCHEDULE"))
      ->capture_default_str();
  cmd->add_option("--repeat", s.repeat, "timed renders per combination")->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--width", s.width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--height", s.height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--camera", s.camera, "camera: index, name, or 'auto'");
  cmd->add_option("--spp", s.settings.ray.spp, "ray tracing: samples per pixel")->check(CLI::Range(1, rt::kMaxSpp))->capture_default_str();
  cmd->add_option("--max-depth", s.settings.ray.maxDepth, "ray tracing: path depth")->check(CLI::Range(1, rt::kMaxDepthLimit))->capture_default_str();
  cmd->add_option("--seed", s.settings.ray.seed, "random seed")->capture_default_str();
  cmd->add_option("--network", s.network, "the network of the predictions:\n" + par::describeNetworks())->capture_default_str();
  cmd->add_option("--max-pes", s.maxPredictedPes, "predict out to this many PEs")->check(CLI::Range(1, 1024))->capture_default_str();
  cmd->add_option("--timeline", s.timelineMethod, "the method whose largest-P run the per-PE bars and the timeline show")
      ->check(CLI::Validator([](std::string& v) { return renderMethods().problem(v); }, "METHOD"))
      ->capture_default_str();
  cmd->add_option("--reference-spp", s.referenceSpp, "the path-traced reference's samples per pixel")
      ->check(CLI::Range(1, rt::kMaxSpp))
      ->capture_default_str();
  cmd->add_option("--reference-dir", s.referenceDir, "where references are cached (default $XDG_CACHE_HOME/parrender/references)");
  cmd->add_option("--photon-spp", s.photonSpp, "the photon map's accuracy curve: samples per pixel, comma-separated")
      ->delimiter(',')
      ->check(CLI::Range(1, rt::kMaxSpp))
      ->capture_default_str();
  cmd->add_option("--photons", s.settings.ray.photonmap.globalPhotons, "photonmap: global photons")
      ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}))
      ->capture_default_str();
  cmd->add_option("--path-spp", s.pathSpp, "the path tracer's accuracy curve: samples per pixel, comma-separated")
      ->delimiter(',')
      ->check(CLI::Range(1, rt::kMaxSpp))
      ->capture_default_str();
  cmd->add_option("--cache-mb", s.cacheMb, "image-space-cached: the cache sizes of the hit-ratio figure, MiB per PE, comma-separated")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1048576.0))
      ->capture_default_str();
  cmd->add_option("--caustic-photons", s.settings.ray.photonmap.causticPhotons, "photonmap: caustic photons")
      ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}))
      ->capture_default_str();
  cmd->add_option("--gather", s.settings.ray.photonmap.gatherRays, "photonmap: final-gather rays per record")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  addLightingOptions(*cmd, s.lighting);
  addFarmOptions(*cmd, s.farm,
                 "under mpirun, image-space also as a farm (render --farm) in the comparison, with a section of its own: "
                 "rank 0 the master, the other ranks servers of each --threads value; a server lost fails the report");
  cmd->callback([a] { run(*a); });
}

}  // namespace pr::cli
