// The series of `parrender sweep` (and of the report's accuracy-against-time curves): the
// photon-map integrator over one varied setting and the path tracer over its samples per
// pixel, each render timed and compared with the path-traced reference (path_reference.h),
// and the CPU time each integrator needs to reach a target RMSE, interpolated on its curve.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/image/image.h"
#include "common/parallel/run_options.h"
#include "photonmap/photon_map_integrator.h"
#include "tools/lighting.h"
#include "tools/sweep/image_error.h"
#include "tools/sweep/path_reference.h"

namespace pr::cli {

// A pixel is in the caustic region when the caustic map gives at least this share of the
// reference's radiance there: the pixels whose light the caustic map carries.
inline constexpr double kCausticShare = 0.25;

struct SweepSpec {
  std::string scene;
  std::string method = "image-space";
  int width = 256, height = 256;
  std::string camera;
  int threads = 1;
  std::string vary = "photons";
  std::vector<double> values;
  std::vector<std::string> integrators = {"photonmap", "path"};
  std::vector<int> pathSpp = {1, 4, 16, 64, 256};
  int spp = 16;  // the photon map's samples per pixel (its render default, kPhotonMapDefaultSpp)
  int maxDepth = 8;
  std::uint64_t seed = 1;
  int referenceSpp = 1024;
  int referenceDepth = 16;
  bool pathSppGiven = false;
  std::string referenceDir;
  bool noCache = false;
  double targetRmse = 0.0;
  std::string images, effects;  // images: folder for every render and its x8 difference, or empty
  pm::PhotonMapSettings photonmap;
  par::ScheduleOptions schedule;
  LightingOptions lighting;
};

struct SweepTimed {
  image::Image image;
  double cpuSeconds = 0.0, wallSeconds = 0.0;
};

struct SweepRow {
  std::string integrator, setting;
  double value = 0.0;
  SweepTimed timed;
  ImageError error;
};

struct SweepResult {
  std::vector<SweepRow> rows;  // the figures of each render (images not kept)
  Reference reference;
  double targetRmse = 0.0;  // given, or the lowest RMSE every integrator reaches
  std::vector<std::pair<std::string, std::optional<double>>> cpuSecondsToTarget;  // per integrator; nullopt: not reached
  std::size_t causticPixels = 0;
  std::string lighting;  // the summary line of what lights the scene
};

// Fills spec.values with the setting's default series when empty. Throws pr::InputError for a
// method that is not a ray tracer, a photon-map setting varied without the photon map, or a
// value the setting cannot take. Progress on stderr, a line per render.
SweepResult runSweep(SweepSpec& spec);

std::string formatValue(double v);  // "%.6g"

}  // namespace pr::cli
