// Screen regions: tile and strip splits of the screen used by every raster pipeline to assign
// region owners (static strips or tiles; demand-driven schedulers hand out the same tiles).
#include "raster/region.h"

#include <algorithm>

#include "common/util/error.h"

namespace pr::raster {

Rect intersect(const Rect& a, const Rect& b) {
  Rect r{std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
  if (r.empty()) return Rect{};
  return r;
}

bool overlaps(const Rect& a, const Rect& b) { return !intersect(a, b).empty(); }

std::vector<Rect> tileRegions(int width, int height, int tileSizePx) {
  PR_CHECK(width >= 0 && height >= 0 && tileSizePx > 0, "tileRegions: bad size");
  std::vector<Rect> tiles;
  for (int y = 0; y < height; y += tileSizePx) {
    for (int x = 0; x < width; x += tileSizePx) {
      tiles.push_back(Rect{x, y, std::min(x + tileSizePx, width), std::min(y + tileSizePx, height)});
    }
  }
  return tiles;
}

std::vector<Rect> stripRegions(int width, int height, int count) {
  PR_CHECK(width >= 0 && height >= 0 && count > 0, "stripRegions: bad size");
  count = std::max(1, std::min(count, height));
  std::vector<Rect> strips;
  // Strip i covers rows [i*h/count, (i+1)*h/count): heights differ by at most one row.
  for (int i = 0; i < count; ++i) {
    int y0 = static_cast<int>(static_cast<long long>(height) * i / count);
    int y1 = static_cast<int>(static_cast<long long>(height) * (i + 1) / count);
    strips.push_back(Rect{0, y0, width, y1});
  }
  return strips;
}

bool cutsByRowCost(std::span<const double> rowCost, int height) {
  double total = 0.0;
  for (double c : rowCost) total += c;
  return rowCost.size() == size_t(height) && total > 0.0;
}

std::vector<Rect> weightedStripRegions(int width, int height, int count, std::span<const double> rowCost) {
  PR_CHECK(width >= 0 && height >= 0 && count > 0, "weightedStripRegions: bad size");
  if (!cutsByRowCost(rowCost, height)) return stripRegions(width, height, count);
  double total = 0.0;
  for (double c : rowCost) total += c;
  count = std::max(1, std::min(count, height));
  std::vector<Rect> strips;
  double sum = 0.0;
  int y = 0;
  for (int i = 0; i < count; ++i) {
    const int y0 = y;
    // Leave at least one row for each strip still to come.
    const int last = height - (count - 1 - i);
    const double share = total * double(i + 1) / double(count);
    do sum += rowCost[size_t(y++)];
    while (y < last && (sum < share || i == count - 1));
    strips.push_back(Rect{0, y0, width, y});
  }
  return strips;
}

}  // namespace pr::raster
