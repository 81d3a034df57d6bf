// The report's data-management figure (seed chapter 4): image-space-cached rendered at the
// largest P once per cache size, with its cache's hit ratio, misses, prefetches, bytes fetched
// and the time the PEs waited for items, as a chart of hit ratio against cache size and a
// table; every image checked against the comparison's image of the same method.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "common/image/image.h"
#include "tools/compare/comparison.h"
#include "tools/report/scene_report.h"
#include "tools/timed_render.h"

namespace pr::cli::report {

// The renders, one comparison per cache size at `threads` PEs per rank (P = threads without
// mpirun), on every rank; under mpirun rank 0 holds their figures. None when P < 2.
struct CacheRun {
  double cacheMb = 0.0;
  Comparison comparison;
};
std::vector<CacheRun> runCacheSweep(const ReportSpec& spec, const RenderInput& input, int threads);

// The section's HTML from the renders at P = pes; its chart's data goes to dir/cache.json.
// `expected` is the image every cache size must give (the comparison's image-space-cached
// image), or nullptr.
std::string cacheSweepSection(const ReportSpec& spec, const std::vector<CacheRun>& runs, int pes,
                              const image::Image* expected, const std::filesystem::path& dir, const std::string& relDir);

}  // namespace pr::cli::report
