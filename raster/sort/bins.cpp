// Binning for the sort points: owners of a triangle's bounds on the sending side, and the
// owner's own regions (bin, rasterize, shade) on the receiving side.
#include "raster/sort/bins.h"

#include <algorithm>
#include <utility>

#include "common/parallel/cell_split.h"
#include "common/parallel/runtime.h"
#include "raster/stages/setup.h"

namespace pr::raster {

void ownersOf(const RegionGrid& grid, const Rect& bounds, std::vector<char>& scratch, std::vector<int>& owners) {
  owners.clear();
  // A large triangle overlaps hundreds of tiles but only P owners: stop once all are found.
  const size_t pes = scratch.size();
  grid.forEachOverlappedWhile(bounds, [&](int r) {
    const int o = grid.owner(r);
    if (!scratch[o]) {
      scratch[o] = 1;
      owners.push_back(o);
    }
    return owners.size() < pes;
  });
  for (int o : owners) scratch[o] = 0;
  std::sort(owners.begin(), owners.end());
}

void RegionDrawer::draw(par::Pe& pe, const ShadingContext& ctx, std::span<const std::vector<ScreenTriangle>> lists,
                        const RegionGrid& grid, std::span<const int> regions, FrameAssembly& frame) {
  slot_.assign(grid.regionCount(), -1);
  for (size_t i = 0; i < regions.size(); ++i) slot_[regions[i]] = static_cast<int>(i);
  // Count, then place: every triangle once per owned region it overlaps, in list order.
  start_.assign(regions.size() + 1, 0);
  for (const std::vector<ScreenTriangle>& list : lists)
    for (const ScreenTriangle& t : list)
      grid.forEachOverlapped(pixelBounds(t), [&](int r) {
        if (slot_[r] >= 0) ++start_[slot_[r] + 1];
      });
  for (size_t i = 0; i < regions.size(); ++i) start_[i + 1] += start_[i];
  binned_ = start_.back();
  if (binned_ > capacity_) {
    capacity_ = binned_ + binned_ / 4;
    storage_ = std::make_unique_for_overwrite<ScreenTriangle[]>(capacity_);
  }
  std::vector<size_t> cursor(start_.begin(), start_.end() - 1);
  for (const std::vector<ScreenTriangle>& list : lists)
    for (const ScreenTriangle& t : list)
      grid.forEachOverlapped(pixelBounds(t), [&](int r) {
        if (slot_[r] >= 0) storage_[cursor[slot_[r]]++] = t;
      });
  // Tiles dealt round-robin are cells the simulator deals again at another P: each one's
  // seconds (drawing and delivering it; the assembler's storing of others' regions meanwhile
  // apart, recorded as the collector's work).
  par::Runtime& rt = pe.runtime();
  const bool recordCells = grid.roundRobin();  // describeTileCells names them
  const double served0 = frame.assembles(pe) ? frame.servedSeconds() : 0.0;
  for (size_t i = 0; i < regions.size(); ++i) {
    const std::span<const ScreenTriangle> bin(storage_.get() + start_[i], start_[i + 1] - start_[i]);
    const Rect& rect = grid.region(regions[i]);
    const double served = frame.assembles(pe) ? frame.servedSeconds() : 0.0;
    const double t0 = recordCells ? rt.now() : 0.0;
    drawOne(pe, ctx, bin, rect, frame);
    if (recordCells) {
      const double storing = frame.assembles(pe) ? frame.servedSeconds() - served : 0.0;
      rt.recordCell(pe, regions[i], rt.now() - t0 - storing, regionMessageBytes(rect));
    }
  }
  if (recordCells && frame.assembles(pe)) rt.recordCell(pe, par::kCollectCell, frame.servedSeconds() - served0, 0);
}

void describeTileCells(par::Runtime& runtime, const RegionGrid& grid) {
  if (grid.roundRobin()) runtime.describeCells(par::kRoundRobinCells, grid.regionCount(), kAssemblerPe);
}

void RegionDrawer::drawOne(par::Pe& pe, const ShadingContext& ctx, std::span<const ScreenTriangle> tris,
                           const Rect& rect, FrameAssembly& frame) {
  if (!frame.assembles(pe)) {
    RegionFramebuffer region = frame.buffer(rect);
    if (rect.area() > kScratchTilePixels) {
      drawRegion(ctx, tris, region.window(), nullptr, &shade_);
    } else {
      scratch_.reshape(rect);
      drawRegion(ctx, tris, scratch_.window(), nullptr, &shade_);
      copyInto(scratch_, region);
    }
    frame.deliver(pe, std::move(region));
    return;
  }
  RegionFramebuffer& image = frame.frame(pe);
  if (rect.area() > kScratchTilePixels) {
    drawRegion(ctx, tris, image.window(rect), nullptr, &shade_);
  } else {
    scratch_.reshape(rect);
    drawRegion(ctx, tris, scratch_.window(), nullptr, &shade_);
    copyInto(scratch_, image);
  }
  frame.serve(pe);  // the regions other PEs finished meanwhile
}

}  // namespace pr::raster
