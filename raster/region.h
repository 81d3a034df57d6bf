// Screen regions: the rectangles that region owners rasterize (tiles or strips). Every raster
// pipeline splits the screen with these functions; sort-first and sort-middle send primitives
// to the owners of the regions they overlap, sort-last composites by region.
#pragma once

#include <span>
#include <vector>

namespace pr::raster {

// A pixel rectangle, half-open: [x0, x1) x [y0, y1); row 0 is the top of the picture.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  long long area() const { return empty() ? 0 : static_cast<long long>(width()) * height(); }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  bool operator==(const Rect&) const = default;
};

Rect intersect(const Rect& a, const Rect& b);
bool overlaps(const Rect& a, const Rect& b);
// The smallest rectangle holding both (an empty one adds nothing). Inline: sort-last calls it
// once per rasterized triangle.
inline Rect enclose(const Rect& a, const Rect& b) {
  if (a.empty()) return b.empty() ? Rect{} : b;
  if (b.empty()) return a;
  return Rect{a.x0 < b.x0 ? a.x0 : b.x0, a.y0 < b.y0 ? a.y0 : b.y0, a.x1 > b.x1 ? a.x1 : b.x1, a.y1 > b.y1 ? a.y1 : b.y1};
}

// Square tiles of tileSizePx (the last row and column may be smaller), in row-major order.
std::vector<Rect> tileRegions(int width, int height, int tileSizePx);

// count horizontal strips of (nearly) equal height, top to bottom; count is clamped to height.
std::vector<Rect> stripRegions(int width, int height, int count);

// count horizontal strips, top to bottom, of (nearly) equal total rowCost (one entry per row,
// >= 0): each strip ends at the first row where the running sum reaches its share, and has at
// least one row. Equal heights (stripRegions) when rowCost does not have `height` entries or
// sums to 0 (cutsByRowCost false).
std::vector<Rect> weightedStripRegions(int width, int height, int count, std::span<const double> rowCost);
// Whether weightedStripRegions cuts by rowCost, not into strips of equal height.
bool cutsByRowCost(std::span<const double> rowCost, int height);

}  // namespace pr::raster
