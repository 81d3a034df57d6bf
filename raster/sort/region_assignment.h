// Region assignment: which PE owns which screen region in the parallel raster pipelines.
// Static strips (one per PE) or static tiles (dealt round-robin) are fixed before the frame;
// every PE holds the same small RegionGrid (replicated, like the camera), so the owners of a
// triangle's bounds are found by two binary searches, never by scanning all regions.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/task.h"
#include "raster/region.h"

namespace pr::raster {

// StaticStrips: one horizontal strip per PE. StaticTiles: tiles dealt round-robin.
// Dynamic: tiles handed out demand-driven by the runtime's scheduler while PEs ask for work
// (tile_pull.h); the grid's owner() is then only where a tile's task would run under a
// static split and the sort points do not use it.
enum class RegionStrategy { StaticStrips, StaticTiles, Dynamic };

// "static-strips" | "static-tiles" | "dynamic"; throws pr::InputError naming the valid values.
RegionStrategy parseRegionStrategy(std::string_view name);
std::string_view regionStrategyName(RegionStrategy strategy);

// The screen cut into a cols x rows grid of regions (strips: 1 column), each with an owner.
class RegionGrid {
 public:
  // Throws pr::InputError for a tile size outside [1, 4096]. pes >= 1.
  RegionGrid(int width, int height, RegionStrategy strategy, int tileSizePx, int pes);

  int regionCount() const { return static_cast<int>(regions_.size()); }
  const Rect& region(int r) const { return regions_[r]; }
  // One task per region, positioned at its centre (for spiral and preferred-bias orders).
  par::TaskSet regionTasks() const;
  int owner(int r) const { return owner_[r]; }
  const std::vector<int>& owners() const { return owner_; }
  bool dynamic() const { return dynamic_; }
  // Regions of PE pe, in row-major order.
  std::vector<int> regionsOf(int pe) const;

  // Calls fn(regionIndex) for every region the pixel rectangle overlaps (clipped to the screen).
  template <class Fn>
  void forEachOverlapped(const Rect& bounds, Fn&& fn) const {
    Rect b = intersect(bounds, screen_);
    if (b.empty()) return;
    const int c0 = cellOf(xs_, b.x0), c1 = cellOf(xs_, b.x1 - 1);
    const int r0 = cellOf(ys_, b.y0), r1 = cellOf(ys_, b.y1 - 1);
    const int cols = static_cast<int>(xs_.size()) - 1;
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) fn(r * cols + c);
  }

 private:
  static int cellOf(const std::vector<int>& edges, int v);

  Rect screen_;
  bool dynamic_ = false;
  std::vector<int> xs_, ys_;  // cell boundaries, first 0, last width/height
  std::vector<Rect> regions_;
  std::vector<int> owner_;
};

}  // namespace pr::raster
