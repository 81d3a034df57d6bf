// RegionAssignment: the region grids cover the screen exactly once, owners are dealt as
// documented, overlap queries find exactly the regions a rectangle touches, and bad names and
// tile sizes are input errors.
#include <doctest/doctest.h>

#include <set>
#include <vector>

#include "common/parallel/cell_split.h"
#include "common/util/error.h"
#include "raster/sort/bins.h"
#include "raster/sort/region_assignment.h"

namespace pr::raster {
namespace {

void checkCover(const RegionGrid& g, int w, int h) {
  std::vector<int> hits(size_t(w) * h, 0);
  for (int r = 0; r < g.regionCount(); ++r)
    for (int y = g.region(r).y0; y < g.region(r).y1; ++y)
      for (int x = g.region(r).x0; x < g.region(r).x1; ++x) hits[size_t(y) * w + x] += 1;
  for (int v : hits) REQUIRE(v == 1);
}

TEST_CASE("RegionAssignment: strips and tiles cover the screen once with the documented owners") {
  RegionGrid strips(50, 30, RegionStrategy::StaticStrips, 16, 4);
  CHECK(strips.regionCount() == 4);
  checkCover(strips, 50, 30);
  for (int r = 0; r < 4; ++r) CHECK(strips.owner(r) == r);
  RegionGrid tiles(50, 30, RegionStrategy::StaticTiles, 16, 3);
  CHECK(tiles.regionCount() == 4 * 2);  // ceil(50/16) x ceil(30/16)
  checkCover(tiles, 50, 30);
  for (int r = 0; r < tiles.regionCount(); ++r) CHECK(tiles.owner(r) == r % 3);
  CHECK(tiles.regionsOf(1) == std::vector<int>{1, 4, 7});
  // More PEs than rows: one strip per row, the extra PEs own nothing.
  RegionGrid thin(8, 3, RegionStrategy::StaticStrips, 16, 7);
  CHECK(thin.regionCount() == 3);
  CHECK(thin.regionsOf(5).empty());
}

TEST_CASE("RegionAssignment: overlap queries match a brute-force scan") {
  RegionGrid tiles(50, 30, RegionStrategy::StaticTiles, 8, 3);
  const Rect probes[] = {{0, 0, 1, 1}, {7, 7, 9, 9}, {-100, -5, 3, 40}, {49, 29, 60, 60}, {8, 8, 16, 16}, {60, 0, 70, 5}};
  for (const Rect& b : probes) {
    std::set<int> fast, brute;
    tiles.forEachOverlapped(b, [&](int r) { fast.insert(r); });
    for (int r = 0; r < tiles.regionCount(); ++r)
      if (overlaps(tiles.region(r), b)) brute.insert(r);
    CHECK(fast == brute);
  }
  std::vector<char> scratch(3, 0);
  std::vector<int> owners;
  ownersOf(tiles, Rect{0, 0, 50, 30}, scratch, owners);
  CHECK(owners == std::vector<int>{0, 1, 2});
  ownersOf(tiles, Rect{9, 1, 10, 2}, scratch, owners);  // tile 1 only
  CHECK(owners == std::vector<int>{1});
}

TEST_CASE("RegionAssignment: static tiles are dealt in proportion to shares, interleaved") {
  // 4 x 2 tiles; PE 1 has three times PE 0's share: tiles 0..7 go 1 1 0 1 1 1 0 1 (each to the
  // PE whose tiles per share grow least, ties to the lower PE), a quarter of them to PE 0.
  const std::vector<double> shares{1.0, 3.0};
  RegionGrid tiles(64, 32, RegionStrategy::StaticTiles, 16, 2, shares);
  checkCover(tiles, 64, 32);
  CHECK(tiles.owners() == std::vector<int>{1, 1, 0, 1, 1, 1, 0, 1});
  // Equal shares deal round-robin, as without shares.
  const std::vector<double> equal{2.0, 2.0, 2.0};
  RegionGrid same(50, 30, RegionStrategy::StaticTiles, 16, 3, equal);
  for (int r = 0; r < same.regionCount(); ++r) CHECK(same.owner(r) == r % 3);
  // The simulator deals cells as c mod P (par::kRoundRobinCells): only such a grid says it is one.
  CHECK(same.roundRobin());
  CHECK_FALSE(tiles.roundRobin());
  CHECK_FALSE(RegionGrid(50, 30, RegionStrategy::StaticStrips, 16, 3).roundRobin());
  CHECK_FALSE(RegionGrid(50, 30, RegionStrategy::Dynamic, 16, 3).roundRobin());
  for (int pes = 1; pes <= 9; ++pes) CHECK(RegionGrid(100, 70, RegionStrategy::StaticTiles, 16, pes).roundRobin());
}

TEST_CASE("RegionAssignment: the simulator's cell splits deal as the regions do") {
  // Tiles dealt in equal shares are round-robin cells; strips of equal height are strip cells
  // (rows), PEs beyond the rows owning none.
  for (int pes = 1; pes <= 12; ++pes)
    for (int height : {1, 5, 7, 16, 30}) {
      CAPTURE(pes);
      CAPTURE(height);
      const RegionGrid tiles(40, height, RegionStrategy::StaticTiles, 4, pes);
      for (int r = 0; r < tiles.regionCount(); ++r)
        CHECK(par::cellOwner(par::kRoundRobinCells, r, tiles.regionCount(), pes) == tiles.owner(r));
      const std::vector<Rect> strips = stripRegions(40, height, pes);
      for (int s = 0; s < static_cast<int>(strips.size()); ++s)
        for (int y = strips[s].y0; y < strips[s].y1; ++y) CHECK(par::cellOwner(par::kStripCells, y, height, pes) == s);
    }
}

TEST_CASE("TileShares: a PE slower per tile gets a smaller share, and balanced times keep the shares") {
  TileShares shares;
  CHECK(shares.forFrame(2).empty());  // the first frame deals equally
  RegionGrid grid(64, 64, RegionStrategy::StaticTiles, 16, 2);  // 8 tiles each
  std::vector<double> busy(2);
  busy[0] = 0.012;  // the assembler: its own tiles and the other PE's stores
  busy[1] = 0.008;
  shares.learn(grid, busy);
  REQUIRE(shares.forFrame(2).size() == 2);
  const double first0 = shares.forFrame(2)[0], first1 = shares.forFrame(2)[1];
  CHECK(first0 < 1.0);
  CHECK(first1 > 1.0);
  CHECK(first0 + first1 == doctest::Approx(2.0));
  CHECK(shares.forFrame(3).empty());  // learnt for another P
  // A frame dealt by these shares in which each PE drew tiles at the rate its share says (so
  // both were equally busy): the shares stay.
  RegionGrid next(64, 64, RegionStrategy::StaticTiles, 16, 2, shares.forFrame(2));
  std::vector<int> tiles(2, 0);
  for (int owner : next.owners()) ++tiles[size_t(owner)];
  CHECK(tiles[0] < tiles[1]);
  busy[0] = 0.001 * tiles[0] / first0;
  busy[1] = 0.001 * tiles[1] / first1;
  shares.learn(next, busy);
  CHECK(shares.forFrame(2)[0] == doctest::Approx(first0).epsilon(0.05));
  CHECK(shares.forFrame(2)[1] == doctest::Approx(first1).epsilon(0.05));
}

TEST_CASE("RegionAssignment: unknown strategy and bad tile size are input errors") {
  CHECK(parseRegionStrategy("static-tiles") == RegionStrategy::StaticTiles);
  CHECK_THROWS_WITH_AS(parseRegionStrategy("diagonal"), doctest::Contains("unknown region assignment 'diagonal'"),
                       InputError);
  CHECK_THROWS_WITH_AS(RegionGrid(10, 10, RegionStrategy::StaticTiles, 0, 2), doctest::Contains("tile size 0"),
                       InputError);
}

}  // namespace
}  // namespace pr::raster
