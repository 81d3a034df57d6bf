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

RegionGrid::RegionGrid(int width, int height, RegionStrategy strategy, int tileSizePx, int pes,
                       std::span<const double> shares)
    : screen_{0, 0, width, height}, dynamic_(strategy == RegionStrategy::Dynamic) {
  PR_CHECK(width > 0 && height > 0 && pes >= 1, "RegionGrid: bad screen or PE count");
  PR_CHECK(shares.empty() || shares.size() == size_t(pes), "RegionGrid: one share per PE");
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
    // Tiles dealt in row-major order, interleaved: neighbouring tiles go to different PEs,
    // which spreads a screen-space hot spot over all of them (static interleaving).
    regions_ = tileRegions(width, height, tileSizePx);
    for (int x = 0; x < width; x += tileSizePx) xs_.push_back(x);
    xs_.push_back(width);
    for (int y = 0; y < height; y += tileSizePx) ys_.push_back(y);
    ys_.push_back(height);
    std::vector<double> dealt(size_t(pes), 0.0);
    for (size_t i = 0; i < regions_.size(); ++i) {
      const auto grown = [&](int p) { return (dealt[size_t(p)] + 1.0) / (shares.empty() ? 1.0 : shares[size_t(p)]); };
      int to = 0;
      for (int p = 1; p < pes; ++p)
        if (grown(p) < grown(to)) to = p;
      dealt[size_t(to)] += 1.0;
      owner_.push_back(to);
    }
    roundRobin_ = !dynamic_;
    for (size_t i = 0; i < owner_.size() && roundRobin_; ++i) roundRobin_ = owner_[i] == static_cast<int>(i % size_t(pes));
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


std::span<const double> TileShares::forFrame(int pes) const {
  if (shares_.size() != size_t(pes)) return {};
  return shares_;
}

void TileShares::learn(const RegionGrid& grid, std::span<const double> busySeconds) {
  const int pes = static_cast<int>(busySeconds.size());
  if (grid.dynamic() || pes < 2) return;
  std::vector<double> tiles(size_t(pes), 0.0);
  for (int owner : grid.owners()) tiles[size_t(owner)] += 1.0;
  // Tiles per busy second; a PE without tiles or without measured time keeps an equal rate.
  std::vector<double> rate(size_t(pes), 0.0);
  double sum = 0.0;
  for (int p = 0; p < pes; ++p) {
    const double busy = busySeconds[size_t(p)];
    rate[size_t(p)] = tiles[size_t(p)] > 0.0 && busy > 0.0 ? tiles[size_t(p)] / busy : 0.0;
    sum += rate[size_t(p)];
  }
  if (sum <= 0.0) return;
  const double mean = sum / pes;
  if (shares_.size() != size_t(pes)) shares_.assign(size_t(pes), 1.0);
  for (int p = 0; p < pes; ++p) {
    const double measured = rate[size_t(p)] > 0.0 ? rate[size_t(p)] / mean : 1.0;
    shares_[size_t(p)] = 0.5 * (shares_[size_t(p)] + measured);
  }
}

}  // namespace pr::raster
