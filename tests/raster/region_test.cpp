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

TEST_CASE("Region: weighted strips hold equal shares of the row cost, each at least one row") {
  // All the cost in rows 10..19 of 100: two strips split it at row 15, four at 12, 15 and 17
  // (the first row where the running sum reaches each share).
  std::vector<double> cost(100, 0.0);
  for (int y = 10; y < 20; ++y) cost[size_t(y)] = 1.0;
  const auto two = weightedStripRegions(64, 100, 2, cost);
  CHECK(partitions(two, 64, 100));
  REQUIRE(two.size() == 2);
  CHECK(two[0] == Rect{0, 0, 64, 15});
  const auto four = weightedStripRegions(64, 100, 4, cost);
  CHECK(partitions(four, 64, 100));
  REQUIRE(four.size() == 4);
  CHECK(four[0].y1 == 13);  // rows 10, 11, 12: 3 >= 2.5
  CHECK(four[1].y1 == 15);
  CHECK(four[2].y1 == 18);  // 8 >= 7.5
  // One costly row and more strips than rows with cost: every strip still gets a row.
  std::vector<double> spike(37, 0.0);
  spike[36] = 5.0;
  for (int strips : {2, 7, 37, 50}) {
    CAPTURE(strips);
    const auto s = weightedStripRegions(100, 37, strips, spike);
    CHECK(partitions(s, 100, 37));
    CHECK(s.size() == static_cast<size_t>(strips < 37 ? strips : 37));
  }
  // Unknown cost (no entries, wrong count, all zero): the equal strips.
  CHECK(weightedStripRegions(64, 100, 3, {}) == stripRegions(64, 100, 3));
  CHECK(weightedStripRegions(64, 100, 3, std::vector<double>(99, 1.0)) == stripRegions(64, 100, 3));
  CHECK(weightedStripRegions(64, 100, 3, std::vector<double>(100, 0.0)) == stripRegions(64, 100, 3));
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
