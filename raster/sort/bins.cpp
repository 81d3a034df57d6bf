// Binning for the sort points: owners of a triangle's bounds on the sending side, and the
// owner's own regions (bin, rasterize, shade) on the receiving side.
#include "raster/sort/bins.h"

#include <algorithm>

#include "raster/stages/rasterize.h"
#include "raster/stages/setup.h"

namespace pr::raster {

void ownersOf(const RegionGrid& grid, const Rect& bounds, std::vector<char>& scratch, std::vector<int>& owners) {
  owners.clear();
  grid.forEachOverlapped(bounds, [&](int r) {
    const int o = grid.owner(r);
    if (!scratch[o]) {
      scratch[o] = 1;
      owners.push_back(o);
    }
  });
  for (int o : owners) scratch[o] = 0;
  std::sort(owners.begin(), owners.end());
}

std::vector<RegionFramebuffer> drawOwnedRegions(const ShadingContext& ctx, std::span<const ScreenTriangle> tris,
                                                const RegionGrid& grid, int pe) {
  const std::vector<int> mine = grid.regionsOf(pe);
  std::vector<int> slot(grid.regionCount(), -1);
  for (size_t i = 0; i < mine.size(); ++i) slot[mine[i]] = static_cast<int>(i);
  // Bin once: each triangle to every owned region its bounds overlap.
  std::vector<std::vector<ScreenTriangle>> bins(mine.size());
  for (const ScreenTriangle& t : tris) {
    grid.forEachOverlapped(pixelBounds(t), [&](int r) {
      if (slot[r] >= 0) bins[slot[r]].push_back(t);
    });
  }
  std::vector<RegionFramebuffer> out;
  out.reserve(mine.size());
  for (size_t i = 0; i < mine.size(); ++i) {
    out.emplace_back(grid.region(mine[i]));
    rasterizeTriangles(bins[i], out.back());
    shadeRegion(ctx, bins[i], out.back());
  }
  return out;
}

}  // namespace pr::raster
