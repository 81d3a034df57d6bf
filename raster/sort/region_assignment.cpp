// Region assignment for the parallel raster pipelines: the region grid (static strips or
// round-robin tiles) and its owners.
#include "raster/sort/region_assignment.h"

#include <algorithm>

#include "common/util/error.h"

namespace pr::raster {

RegionStrategy parseRegionStrategy(std::string_view name) {
  if (name == "static-strips") return RegionStrategy::StaticStrips;
  if (name == "static-tiles") return RegionStrategy::StaticTiles;
  if (name == "dynamic") return RegionStrategy::Dynamic;
  throw InputError("unknown region assignment '" + std::string(name) +
                   "' (expected static-strips, static-tiles or dynamic)");
}

std::string_view regionStrategyName(RegionStrategy strategy) {
  switch (strategy) {
    case RegionStrategy::StaticStrips: return "static-strips";
    case RegionStrategy::StaticTiles: return "static-tiles";
    case RegionStrategy::Dynamic: return "dynamic";
  }
  return "?";
}

RegionGrid::RegionGrid(int width, int height, RegionStrategy strategy, int tileSizePx, int pes)
    : screen_{0, 0, width, height}, dynamic_(strategy == RegionStrategy::Dynamic) {
  PR_CHECK(width > 0 && height > 0 && pes >= 1, "RegionGrid: bad screen or PE count");
  if (tileSizePx < 1 || tileSizePx > 4096)
    throw InputError("tile size " + std::to_string(tileSizePx) + " px is outside [1, 4096]");
  if (strategy == RegionStrategy::StaticStrips) {
    // One strip per PE (fewer when the screen has fewer rows than PEs): PE i owns strip i.
    regions_ = stripRegions(width, height, pes);
    xs_ = {0, width};
    ys_.push_back(0);
    for (const Rect& s : regions_) ys_.push_back(s.y1);
    for (int i = 0; i < static_cast<int>(regions_.size()); ++i) owner_.push_back(i);
  } else {
    // Tiles dealt round-robin in row-major order: neighbouring tiles go to different PEs,
    // which spreads a screen-space hot spot over all of them (static interleaving).
    regions_ = tileRegions(width, height, tileSizePx);
    for (int x = 0; x < width; x += tileSizePx) xs_.push_back(x);
    xs_.push_back(width);
    for (int y = 0; y < height; y += tileSizePx) ys_.push_back(y);
    ys_.push_back(height);
    for (int i = 0; i < static_cast<int>(regions_.size()); ++i) owner_.push_back(i % pes);
  }
}

par::TaskSet RegionGrid::regionTasks() const {
  par::TaskSet set = par::TaskSet::uniform(regions_.size());
  for (size_t r = 0; r < regions_.size(); ++r) {
    set.tasks[r].x = 0.5f * float(regions_[r].x0 + regions_[r].x1);
    set.tasks[r].y = 0.5f * float(regions_[r].y0 + regions_[r].y1);
  }
  return set;
}

std::vector<int> RegionGrid::regionsOf(int pe) const {
  std::vector<int> mine;
  for (int r = 0; r < regionCount(); ++r)
    if (owner_[r] == pe) mine.push_back(r);
  return mine;
}

int RegionGrid::cellOf(const std::vector<int>& edges, int v) {
  // edges is increasing with edges.front() <= v < edges.back(): the cell whose start is <= v.
  return static_cast<int>(std::upper_bound(edges.begin(), edges.end(), v) - edges.begin()) - 1;
}

}  // namespace pr::raster
