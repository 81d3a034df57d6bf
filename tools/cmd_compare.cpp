// `parrender compare SCENE --methods LIST --threads LIST --schedules LIST [--integrators LIST]
// [--compositors LIST] [--repeat N]`: every valid combination rendered afresh N times
// (compare/comparison.h), one table of the measured figures (compare/comparison_output.h),
// the skipped combinations with their reasons, and a loud failure (exit status 1) when an
// image differs from its family's. --json and --csv write the rows for programs.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/image/codec_loader.h"
#include "common/image/image_io.h"
#include "common/parallel/process_group.h"
#include "common/parallel/run_options.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "tools/commands.h"
#include "tools/compare/comparison.h"
#include "tools/compare/comparison_output.h"
#include "tools/integrators.h"
#include "tools/lighting.h"
#include "tools/render_methods.h"
#include "tools/sweep/image_error.h"

namespace pr::cli {

namespace {

struct CompareArgs {
  std::string scene;
  int width = 256, height = 256;
  std::string camera, effects;
  std::vector<std::string> methods, schedules = {"demand"}, integrators = {"path"}, compositors = {"direct-send"};
  std::vector<int> threads;
  int repeat = 3;
  bool noReference = false, quiet = false;
  int referenceSpp = 256, referenceDepth = 16;
  std::string referenceDir;
  bool noCache = false;
  std::string json, csv, images;
  par::ScheduleOptions schedule;
  RenderSettings settings;
  FamilyOptions family;
  LightingOptions lighting;
  FarmArgs farm;
};

// A file name for a row's image: its label with spaces and '=' made safe.
std::string fileStem(const Combination& c) {
  std::string s = c.label();
  std::replace(s.begin(), s.end(), ' ', '_');
  std::replace(s.begin(), s.end(), '=', '-');
  std::replace(s.begin(), s.end(), '(', '_');
  s.erase(std::remove(s.begin(), s.end(), ')'), s.end());
  return s;
}

void run(CompareArgs& a) {
  if (a.methods.empty())
    for (std::string_view m : renderMethods().names()) a.methods.emplace_back(m);
  // Under mpirun, --threads is each rank's PEs and rank 0 prints and writes.
  const int ranks = par::ProcessGroup::get().ranks();
  const bool writes = holdsResults();
  checkFarm(a.farm, findRenderMethod("image-space"), a.settings, ranks);
  if (a.threads.empty()) a.threads = defaultThreadCounts();
  ComparisonSpec spec;
  spec.methods = a.methods;
  spec.schedules = a.schedules;
  spec.integrators = a.integrators;
  spec.compositors = a.compositors;
  spec.threads = a.threads;
  spec.repeat = a.repeat;
  spec.settings = a.settings;
  spec.scheduleParams = a.schedule.params;
  spec.progress = !a.quiet;
  spec.keepImages = !a.images.empty();
  spec.reference = !a.noReference;
  spec.farm = a.farm;
  spec.referenceSettings = ReferenceSettings{a.scene, a.camera, a.effects, a.lighting, a.referenceSpp, a.referenceDepth,
                                             a.settings.ray.seed, a.referenceDir, a.noCache, "image-space",
                                             everyRank(*std::max_element(a.threads.begin(), a.threads.end())), {}};

  // Options of one family given to a comparison with methods of the other: they apply where
  // they can and are noted for the rest.
  bool photonmap = std::find(a.integrators.begin(), a.integrators.end(), "photonmap") != a.integrators.end();
  for (const CLI::Option* o : a.settings.ray.photonOptions)
    if (o->count() > 0 && !photonmap)
      throw InputError(o->get_name() + " applies to the photonmap integrator; add it to --integrators");
  spec.settings.ray.photonOptions.clear();  // checked above, for every combination at once
  for (const auto& [option, family] : a.family) {
    if (option->count() == 0) continue;
    std::string others;
    for (const std::string& m : a.methods)
      if (findRenderMethod(m).properties.family != family) others += (others.empty() ? "" : ", ") + m;
    if (!others.empty())
      spec.notes.push_back(option->get_name() + " is a " + std::string(toString(family)) + " option; " + others +
                           " ran without it");
  }
  for (const std::string& m : a.methods)
    if (findRenderMethod(m).properties.family == MethodFamily::Raster && a.integrators != std::vector<std::string>{"path"}) {
      spec.notes.push_back("--integrators applies to the ray tracers; the rasterizers ran once each");
      break;
    }

  const scene::EffectOverrides overrides = scene::parseEffectOverrides(a.effects);
  scene::Scene scene = loadScene(a.scene, a.lighting);
  const std::string lighting = applyLighting(scene, a.lighting);
  const scene::Camera camera = scene::selectCamera(scene, a.camera, float(a.width) / float(a.height));
  const scene::RenderPlan plan = scene::applyOverrides(scene::analyzeEffects(scene, &camera), overrides);
  if (!a.images.empty() && writes) {
    std::filesystem::create_directories(a.images);
    image::imageCodec();  // opened before the first timed render, never beside it
  }

  const Comparison c = runComparison(spec, RenderInput{scene, camera, plan, a.width, a.height});
  if (!writes) return;

  std::printf("compare %s, %dx%d, %d run%s per combination (median wall time, spread = (max - min) / 2 / median; messages and bytes of every kind)\n",
              a.scene.c_str(), a.width, a.height, a.repeat, a.repeat == 1 ? "" : "s");
  std::printf("%s\n", lighting.c_str());
  if (ranks > 1)
    std::printf("across %d ranks launched by mpirun: P = %d x PEs per rank (--threads); P = 1 on rank 0 alone while "
                "the others waited\n", ranks, ranks);
  if (a.farm.enabled)
    std::printf("image-space farm: rank 0 the master, the other %d ranks servers; P counts the servers' PEs, the schedule is "
                "among each server's PEs, the master orders jobs of %s by %s\n",
                ranks - 1, a.farm.job.c_str(), a.farm.schedule.c_str());
  std::printf("T1/Tn against the same combination at P=1, Ts/Tn against the family's one-PE reference (sequential, "
              "sequential-raster; else its fastest at P=1)");
  if (!c.reference.image.empty())
    std::printf("; rmse against a path-traced reference, %d spp, depth %d%s", a.referenceSpp, a.referenceDepth,
                c.reference.cached ? " (cached)" : "");
  std::printf("\n");
  std::printf("%s%s", comparisonTable(c).c_str(), comparisonNotes(c).c_str());

  if (!a.csv.empty()) writeFileAtomically(a.csv, comparisonCsv(c), "CSV file");
  if (!a.json.empty()) {
    nlohmann::json j = comparisonJson(c);
    j["scene"] = a.scene;  // written with invalid UTF-8 replaced (dump below)
    j["width"] = a.width;
    j["height"] = a.height;
    j["repeat"] = a.repeat;
    if (!c.reference.image.empty()) j["reference"]["spp"] = a.referenceSpp;
    writeFileAtomically(a.json, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", "JSON file");
  }
  if (!a.images.empty()) {
    const std::filesystem::path dir(a.images);
    for (const ComparisonRow& r : c.rows) {
      image::writeImage((dir / (fileStem(r.what) + ".png")).string(), r.image);
      if (!c.reference.image.empty())
        image::writeImage((dir / (fileStem(r.what) + "_diff8.png")).string(), differenceImage(r.image, c.reference.image));
    }
    if (!c.reference.image.empty()) image::writeImage((dir / "reference.png").string(), c.reference.image);
  }
  if (c.mismatches > 0)
    throw std::runtime_error(std::to_string(c.mismatches) + " render(s) differ from their family's image (IMAGE MISMATCH above)");
}

// Removes a single-valued option the compare command takes as a list instead.
void replaceWithList(CLI::App& cmd, FamilyOptions& family, const std::string& name) {
  CLI::Option* single = cmd.get_option(name);
  family.erase(std::remove_if(family.begin(), family.end(), [&](const auto& f) { return f.first == single; }), family.end());
  cmd.remove_option(single);
}

}  // namespace

void addCompareCommand(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "render every valid combination of methods, P, schedules and integrators; one table of measured figures");
  cmd->add_option("scene", a->scene, "glTF 2.0 scene (.gltf or .glb)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--methods", a->methods, "render methods, comma-separated (default: all):\n" + describeRenderMethods())
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return renderMethods().problem(v); }, "METHOD"));
  cmd->add_option("--threads", a->threads, "values of P, comma-separated (default: 1, 2, 4, ... and this machine's cores); under mpirun, PEs per rank "
                "(P = ranks x each, default 1) and P = 1 on rank 0 alone")
      ->delimiter(',')
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--schedules", a->schedules, "schedules, comma-separated:\n" + par::describeSchedules())
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return par::schedules().problem(v); }, "SCHEDULE"))
      ->capture_default_str();
  par::addScheduleOptions(*cmd, a->schedule);
  cmd->remove_option(cmd->get_option("--schedule"));
  addRayOptions(*cmd, a->settings, a->family);
  addRasterOptions(*cmd, a->settings, a->family);
  replaceWithList(*cmd, a->family, "--integrator");
  replaceWithList(*cmd, a->family, "--compositor");
  cmd->add_option("--integrators", a->integrators, "ray tracing: integrators, comma-separated")
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return integrators().problem(v); }, "INTEGRATOR"))
      ->capture_default_str();
  cmd->add_option("--compositors", a->compositors, "sort-last: compositors, comma-separated")
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& v) { return raster::compositors().problem(v); }, "COMPOSITOR"))
      ->capture_default_str();
  cmd->add_option("--repeat", a->repeat, "timed renders per combination (median and spread kept)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--width", a->width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--height", a->height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--camera", a->camera, "camera: index, name, or 'auto'");
  cmd->add_option("--effects", a->effects, "force effects on or off, as for render");
  cmd->add_flag("--no-reference", a->noReference, "no path-traced reference and no rmse column");
  cmd->add_option("--reference-spp", a->referenceSpp, "the reference's samples per pixel")
      ->check(CLI::Range(1, rt::kMaxSpp))
      ->capture_default_str();
  cmd->add_option("--reference-depth", a->referenceDepth, "the reference's path depth")
      ->check(CLI::Range(1, rt::kMaxDepthLimit))
      ->capture_default_str();
  cmd->add_option("--reference-dir", a->referenceDir, "where references are cached (default $XDG_CACHE_HOME/parrender/references)");
  cmd->add_flag("--no-cache", a->noCache, "render the reference afresh and do not store it");
  cmd->add_option("--json", a->json, "write the rows, skipped combinations and agreement as JSON");
  cmd->add_option("--csv", a->csv, "write the rows as CSV");
  cmd->add_option("--images", a->images, "folder for each row's image (PNG) and its x8 difference from the reference");
  cmd->add_flag("--quiet", a->quiet, "no progress lines");
  addLightingOptions(*cmd, a->lighting);
  addFarmOptions(*cmd, a->farm,
                 "under mpirun, image-space also as a farm (render --farm), after every other render: rank 0 the master, "
                 "the other ranks servers of each --threads value; a server lost fails the comparison");
  cmd->callback([a] { run(*a); });
}

}  // namespace pr::cli
