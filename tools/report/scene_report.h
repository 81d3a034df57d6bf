// One scene's part of `parrender report`: the comparison run, the accuracy sweep, the
// simulator's predictions, and every table, image and chart of the scene's section, written
// into the scene's folder of the report (images, chart data, the comparison as CSV and JSON,
// the chosen run's record and Chrome trace).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tools/farm_render.h"
#include "tools/lighting.h"
#include "tools/render_methods.h"

namespace pr::cli::report {

struct ReportSpec {
  std::vector<std::string> methods, schedules;
  std::vector<int> threads;
  int repeat = 3;
  int width = 256, height = 256;
  std::string camera;
  RenderSettings settings;   // spp, depth, seed and the rest
  std::string network = "1gbe";
  int maxPredictedPes = 1024;
  std::string timelineMethod = "object-space";  // whose largest-P run the per-PE bars and Gantt show
  int referenceSpp = 256;
  std::filesystem::path referenceDir;  // empty: the default cache
  // The accuracy curves: samples per pixel of the photon map (its photon counts and gather
  // settings from settings.ray.photonmap) and of the path tracer.
  std::vector<int> photonSpp = {1, 4, 16};
  std::vector<int> pathSpp = {1, 4, 16, 64};
  // Cache sizes (MiB per PE) of the data-management figure, drawn when image-space-cached is
  // among the methods.
  std::vector<double> cacheMb = {0.0, 0.25, 1.0, 4.0, 16.0, 64.0};
  LightingOptions lighting;
  FarmArgs farm;  // with farm.enabled, under mpirun: image-space also as a farm (farm_section.h)
};

// Writes the scene's files under dir (created) and returns its HTML section; `relDir` is dir
// as index.html links it.
struct SceneSection {
  std::string html;
  int mismatches = 0;  // renders whose image differs from their family's (on rank 0; 0 elsewhere)
};
SceneSection sceneReport(const std::string& sceneFile, const ReportSpec& spec, const std::filesystem::path& dir,
                         const std::string& relDir);

}  // namespace pr::cli::report
