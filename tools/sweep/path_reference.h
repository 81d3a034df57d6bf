// The reference every error figure of sweep, compare and report is measured against: a long
// path-traced render of the scene with its own random stream, taken from the reference cache
// (reference_cache.h) when one with exactly these settings is on disk, else rendered (with
// progress on stderr) and stored. Under mpirun, rank 0 looks in the cache and tells the
// others; a reference to render is rendered across every rank (`where`), and stored by rank 0,
// which alone holds its image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "common/image/image.h"
#include "common/parallel/run_options.h"
#include "tools/lighting.h"
#include "tools/timed_render.h"

namespace pr::cli {

struct ReferenceSettings {
  std::string sceneFile, camera, effects;  // as given on the command line (part of the cache key)
  LightingOptions lighting;
  int spp = 1024, maxDepth = 16;
  std::uint64_t seed = 1;  // the series' seed; the reference's stream is apart from it
  std::filesystem::path dir;  // empty: ReferenceCache::defaultDir()
  bool noCache = false;       // render afresh and do not store
  std::string method = "image-space";  // how it is rendered (the image does not depend on it)
  Placement where;
  par::ScheduleOptions schedule;
};

struct Reference {
  image::Image image;
  bool cached = false;
  double cpuSeconds = 0.0;     // 0 when cached
  std::filesystem::path file;  // where it is stored, empty with noCache
};

Reference pathReference(const ReferenceSettings& settings, const RenderInput& input);

}  // namespace pr::cli
