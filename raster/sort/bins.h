// Binning, the step on both sides of a sort: a sender groups what it has by the owners of the
// screen regions it overlaps (one message per owner), and an owner groups what it received by
// its own regions before drawing them and delivering each finished region to the assembler
// (frame_assembly.h). Shared by sort-first and sort-middle.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "common/parallel/pe.h"
#include "raster/frame_assembly.h"
#include "raster/framebuffer.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/draw_region.h"
#include "raster/stages/geometry.h"
#include "raster/stages/shade.h"

namespace pr::raster {

// Distinct owners of the regions a pixel rectangle overlaps, in increasing PE order; scratch
// is a per-caller mark buffer of size P (all zero on entry and on return).
void ownersOf(const RegionGrid& grid, const Rect& bounds, std::vector<char>& scratch, std::vector<int>& owners);

// An owner's regions drawn from the screen triangles it holds: each triangle is binned to every
// one of those regions its pixel bounds overlap (a counting sort into one array, whose storage
// is kept from frame to frame), then each region is drawn and delivered (drawOne). One per PE;
// used only by that PE, inside its tasks.
inline constexpr long long kScratchTilePixels = 128 * 128;
class RegionDrawer {
 public:
  // Draws regions (indices into grid) from the triangles of every list in lists. On a grid of
  // tiles dealt round-robin each tile is a cell of the stage (Runtime::recordCell), which the
  // stage's caller then names with describeTileCells.
  void draw(par::Pe& pe, const ShadingContext& ctx, std::span<const std::vector<ScreenTriangle>> lists,
            const RegionGrid& grid, std::span<const int> regions, FrameAssembly& frame);

  // Draws region rect from tris and delivers it to the frame. A region up to
  // kScratchTilePixels is drawn in this PE's scratch buffer, where clearing, depth tests and
  // shading stay in cache, and then copied once: into the frame on the assembler, into a
  // message buffer of the assembly's pool on any other PE. A larger one (a strip) is drawn in
  // the frame or the message buffer directly. (A pool buffer was last read by the assembler, so
  // drawing in it took every line back from the assembler's cache, pass after pass: on the
  // Cornell box at P = 2 the copy made sort-middle's frame about 9% faster.)
  void drawOne(par::Pe& pe, const ShadingContext& ctx, std::span<const ScreenTriangle> tris, const Rect& rect,
               FrameAssembly& frame);

  // Triangles binned by the last draw (a triangle counts once per region it went to).
  size_t binned() const { return binned_; }
  // What shading did and skipped since the last call, then reset.
  ShadeCounters takeShadeCounters() { return std::exchange(shade_, ShadeCounters{}); }

 private:
  std::unique_ptr<ScreenTriangle[]> storage_;  // uninitialised beyond what draw() writes
  size_t capacity_ = 0;
  size_t binned_ = 0;
  std::vector<int> slot_;       // grid region -> position in regions, or -1
  std::vector<size_t> start_;   // per position: first index in storage_
  RegionFramebuffer scratch_;
  ShadeCounters shade_;
};

// After a stage whose PEs drew with RegionDrawer::draw on grid: names its tiles as the stage's
// cells (par::kRoundRobinCells, collected by the assembler) when draw recorded them.
void describeTileCells(par::Runtime& runtime, const RegionGrid& grid);


}  // namespace pr::raster
