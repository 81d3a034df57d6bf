// Screen cells: sort-first and sort-middle on static tiles dealt round-robin record every tile
// as a cell of their draw stage (its seconds, the bytes of its region message) and the
// assembler's storing of other PEs' regions; sort-last on direct-send's strips of equal height
// records each shaded row, and its clear as work each PE does in full. The simulator deals the
// cells again at another P (common/parallel/stage_replay.h); strips of the sort points that
// deliver regions, and tiles dealt by learnt shares, are not cells.
#include <doctest/doctest.h>

#include <string>

#include "common/parallel/cell_split.h"
#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "raster/frame_assembly.h"
#include "raster/parallel_pipeline.h"
#include "raster/sort/sort_test_support.h"

namespace pr::raster {
namespace {

const par::StageRecord* stageNamed(const par::RunRecord& record, const std::string& name, int& index) {
  for (std::size_t s = record.stages.size(); s-- > 0;)
    if (record.stages[s].name == name) {
      index = static_cast<int>(s);
      return &record.stages[s];
    }
  return nullptr;
}

TEST_CASE("ScreenCells: a draw stage on round-robin tiles records each tile once, on its owner, with its region's bytes") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();  // 16 x 16: four 8 x 8 tiles
  SortOptions options;
  options.regions = RegionStrategy::StaticTiles;
  options.tileSizePx = 8;
  for (const char* method : {"sort-first", "sort-middle"}) {
    CAPTURE(method);
    par::Runtime rt(3, "demand");
    renderParallel(s, view, method, options, rt);
    int index = -1;
    const par::StageRecord* draw = stageNamed(rt.record(), std::string(method) + (std::string(method) == "sort-first" ? " render" : " rasterize"), index);
    REQUIRE(draw != nullptr);
    CHECK(draw->cellSplit == par::kRoundRobinCells);
    CHECK(draw->cellCollector == kAssemblerPe);
    int seen[4] = {0, 0, 0, 0};
    int collects = 0;
    for (const par::CellSpan& c : rt.record().cells) {
      REQUIRE(c.stage == index);
      if (c.cell == par::kCollectCell) {
        CHECK(c.pe == kAssemblerPe);
        ++collects;
        continue;
      }
      REQUIRE(c.cell >= 0);
      REQUIRE(c.cell < 4);
      seen[c.cell] += 1;
      CHECK(c.pe == c.cell % 3);
      CHECK(c.resultBytes == kRegionHeaderBytes + 64 * kRegionPixelBytes);
    }
    for (int n : seen) CHECK(n == 1);
    CHECK(collects == 1);
    // The simulator reads tiles 1 and 2 as the results stored by the assembler.
    const par::Workload w = par::workloadFromRecord(rt.record(), "test");
    CHECK(w.stages[static_cast<std::size_t>(index)].collectedCells == 2);
  }
}

TEST_CASE("ScreenCells: strips are no cells, nor tiles dealt by shares learnt from a frame") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions strips;
  strips.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "demand");
  renderParallel(s, view, "sort-middle", strips, rt);
  CHECK(rt.record().cells.empty());
  for (const par::StageRecord& stage : rt.record().stages) CHECK(stage.cellSplit.empty());
  // Sort-middle's second frame deals by the shares the first one learnt: unless they came out
  // equal, that frame's rasterize stage has no cells.
  SortOptions tiles;
  tiles.regions = RegionStrategy::StaticTiles;
  tiles.tileSizePx = 4;
  par::Runtime two(2, "demand");
  std::unique_ptr<SortPoint> sm = makeSortPoint("sort-middle");
  renderFrame(*sm, s, view, tiles, two);
  renderFrame(*sm, s, view, tiles, two);
  const par::RunRecord& r = two.record();
  const par::StageRecord& second = r.stages.back();
  REQUIRE(second.name == "sort-middle rasterize");
  bool cellsInSecond = false;
  for (const par::CellSpan& c : r.cells) cellsInSecond = cellsInSecond || c.stage == static_cast<int>(r.stages.size()) - 1;
  CHECK(cellsInSecond == !second.cellSplit.empty());
}

TEST_CASE("ScreenCells: sort-last shades rows as strip cells on direct-send's equal strips, and clears in full") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();  // 16 rows
  SortOptions options;
  options.compositor = "direct-send";
  par::Runtime rt(3, "demand");
  renderParallel(s, view, "sort-last", options, rt);
  int index = -1;
  const par::StageRecord* shade = stageNamed(rt.record(), "sort-last shade", index);
  REQUIRE(shade != nullptr);
  CHECK(shade->cellSplit == par::kStripCells);
  CHECK(shade->cellCount == 16);
  CHECK(shade->cellCollector == -1);
  int rows = 0;
  for (const par::CellSpan& c : rt.record().cells) {
    REQUIRE(c.stage == index);
    CHECK(c.pe == par::cellOwner(par::kStripCells, c.cell, 16, 3));  // rows 0-4, 5-9, 10-15
    CHECK(c.resultBytes == 0);
    ++rows;
  }
  CHECK(rows > 0);
  CHECK(rows <= 16);
  int clear = -1;
  REQUIRE(stageNamed(rt.record(), "sort-last clear", clear) != nullptr);
  CHECK(rt.record().stages[static_cast<std::size_t>(clear)].kind == par::kEachPeInFullStage);
  // Binary swap's halves are no strips: no cells.
  options.compositor = "binary-swap";
  par::Runtime four(4, "demand");
  renderParallel(s, view, "sort-last", options, four);
  CHECK(four.record().cells.empty());
}

}  // namespace
}  // namespace pr::raster
