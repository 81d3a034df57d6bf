// Tests of screen regions: tile and strip splits partition the screen exactly.
#include <doctest/doctest.h>

#include <cstddef>
#include <vector>

#include "raster/region.h"

namespace pr::raster {
namespace {

// Every pixel must belong to exactly one region.
bool partitions(const std::vector<Rect>& regions, int width, int height) {
  std::vector<int> count(static_cast<size_t>(width) * height, 0);
  for (const Rect& r : regions) {
    if (r.x0 < 0 || r.y0 < 0 || r.x1 > width || r.y1 > height || r.empty()) return false;
    for (int y = r.y0; y < r.y1; ++y) {
      for (int x = r.x0; x < r.x1; ++x) ++count[static_cast<size_t>(y) * width + x];
    }
  }
  for (int c : count) {
    if (c != 1) return false;
  }
  return true;
}

TEST_CASE("Region: tiles and strips partition the screen") {
  for (int tile : {1, 7, 16, 64, 500}) {
    CAPTURE(tile);
    CHECK(partitions(tileRegions(100, 37, tile), 100, 37));
  }
  // 100x37 in tiles of 16: ceil(100/16) * ceil(37/16) = 7 * 3, the last column 4 px wide.
  auto tiles = tileRegions(100, 37, 16);
  CHECK(tiles.size() == 21);
  CHECK(tiles.back() == Rect{96, 32, 100, 37});
  for (int strips : {1, 2, 3, 7, 37, 50}) {
    CAPTURE(strips);
    auto s = stripRegions(100, 37, strips);
    CHECK(partitions(s, 100, 37));
    CHECK(s.size() == static_cast<size_t>(strips < 37 ? strips : 37));
    // Heights differ by at most one row.
    int lo = 1 << 30, hi = 0;
    for (const Rect& r : s) {
      lo = r.height() < lo ? r.height() : lo;
      hi = r.height() > hi ? r.height() : hi;
    }
    CHECK(hi - lo <= 1);
  }
}

TEST_CASE("Region: intersection and overlap") {
  Rect a{0, 0, 10, 10}, b{5, 8, 20, 30}, c{10, 0, 20, 10};
  CHECK(intersect(a, b) == Rect{5, 8, 10, 10});
  CHECK(overlaps(a, b));
  CHECK_FALSE(overlaps(a, c));  // half-open: touching edges share no pixel
  CHECK(intersect(a, c).empty());
  CHECK(intersect(a, b).area() == 10);
}

}  // namespace
}  // namespace pr::raster
