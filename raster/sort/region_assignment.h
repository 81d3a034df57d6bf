// Region assignment: which PE owns which screen region in the parallel raster pipelines.
// Static strips (one per PE) or static tiles (dealt round-robin, or in proportion to shares
// learnt from the previous frame: TileShares) are fixed before the frame;
// every PE holds the same small RegionGrid (replicated, like the camera), so the owners of a
// triangle's bounds are found by two binary searches, never by scanning all regions.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/run_record.h"
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
  // Throws pr::InputError for a tile size outside [1, 4096]. pes >= 1. Static tiles are dealt
  // in proportion to shares (one positive value per PE; equal when empty): in row-major order,
  // each tile to the PE whose tiles per share grow least by it (ties to the lower PE), so equal
  // shares deal round-robin and neighbouring tiles still go to different PEs.
  RegionGrid(int width, int height, RegionStrategy strategy, int tileSizePx, int pes,
             std::span<const double> shares = {});

  int regionCount() const { return static_cast<int>(regions_.size()); }
  const Rect& region(int r) const { return regions_[r]; }
  // One task per region, positioned at its centre (for spiral and preferred-bias orders).
  par::TaskSet regionTasks() const;
  int owner(int r) const { return owner_[r]; }
  const std::vector<int>& owners() const { return owner_; }
  bool dynamic() const { return dynamic_; }
  // Static tiles dealt round-robin (equal shares): tile r on PE r mod P, a split the simulator
  // can make again at any P from the tiles' measured costs (par::kRoundRobinCells).
  bool roundRobin() const { return roundRobin_; }
  // Regions of PE pe, in row-major order.
  std::vector<int> regionsOf(int pe) const;

  // Calls fn(regionIndex) for every region the pixel rectangle overlaps (clipped to the screen).
  template <class Fn>
  void forEachOverlapped(const Rect& bounds, Fn&& fn) const {
    forEachOverlappedWhile(bounds, [&](int region) {
      fn(region);
      return true;
    });
  }
  // The same, in row-major order, until fn returns false.
  template <class Fn>
  void forEachOverlappedWhile(const Rect& bounds, Fn&& fn) const {
    Rect b = intersect(bounds, screen_);
    if (b.empty()) return;
    const int c0 = cellOf(xs_, b.x0), c1 = cellOf(xs_, b.x1 - 1);
    const int r0 = cellOf(ys_, b.y0), r1 = cellOf(ys_, b.y1 - 1);
    const int cols = static_cast<int>(xs_.size()) - 1;
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c)
        if (!fn(r * cols + c)) return;
  }

 private:
  static int cellOf(const std::vector<int>& edges, int v);

  Rect screen_;
  bool dynamic_ = false;
  bool roundRobin_ = false;
  std::vector<int> xs_, ys_;  // cell boundaries, first 0, last width/height
  std::vector<Rect> regions_;
  std::vector<int> owner_;
};

// The shares of static tiles, learnt from frame to frame by the sort points that deliver regions
// to the assembler (sort-first, sort-middle). PE 0 also stores every region the other PEs
// deliver (frame_assembly.h), so with equal shares it finishes last. After each frame a PE's
// share becomes proportional to the tiles it drew per second of its busy time in that frame's
// draw stage (the runtime's measurement), averaged with its previous share. The first frame,
// and any frame after P changed, deals equally. Images do not depend on the shares (regions
// are disjoint); only which PE draws which tile, and so the traffic, does.
class TileShares {
 public:
  // The shares for a frame on `pes` PEs (empty: deal equally).
  std::span<const double> forFrame(int pes) const;
  // After the frame drawn with `grid`: learns from each PE's busy seconds in its draw stage
  // (across ranks, every rank's PEs: the same figures on every rank, so every rank deals the
  // next frame's tiles alike).
  void learn(const RegionGrid& grid, std::span<const double> busySeconds);

 private:
  std::vector<double> shares_;
};

}  // namespace pr::raster
