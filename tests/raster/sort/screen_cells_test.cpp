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
    CHECK(w.stages[static_cast<std::size_t>(index)].resultsToCollector == 2);
  }
}

TEST_CASE("ScreenCells: the strips of the sort points that deliver regions are no cells") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions strips;
  strips.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "demand");
  renderParallel(s, view, "sort-middle", strips, rt);
  CHECK(rt.record().cells.empty());
  for (const par::StageRecord& stage : rt.record().stages) CHECK(stage.cellSplit.empty());
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
  // No collector: no row's result counts as sent anywhere.
  CHECK(par::workloadFromRecord(rt.record(), "test").stages[static_cast<std::size_t>(index)].resultsToCollector == 0);
  int clear = -1;
  REQUIRE(stageNamed(rt.record(), "sort-last clear", clear) != nullptr);
  CHECK(rt.record().stages[static_cast<std::size_t>(clear)].kind == par::kEachPeInFullStage);
  // Binary swap's halves are no strips, even at P = 1 where its one region is the screen.
  options.compositor = "binary-swap";
  for (int pes : {1, 4}) {
    CAPTURE(pes);
    par::Runtime swap(pes, "demand");
    renderParallel(s, view, "sort-last", options, swap);
    CHECK(swap.record().cells.empty());
  }
  // Direct-send's second frame cuts its strips at the first frame's shading work: no cells.
  options.compositor = "direct-send";
  par::Runtime two(2, "demand");
  std::unique_ptr<SortPoint> sl = makeSortPoint("sort-last");
  renderFrame(*sl, s, view, options, two);
  const std::size_t firstFrameCells = two.record().cells.size();
  CHECK(firstFrameCells > 0);
  renderFrame(*sl, s, view, options, two);
  CHECK(two.record().cells.size() == firstFrameCells);
  int second = -1;
  REQUIRE(stageNamed(two.record(), "sort-last shade", second) != nullptr);
  CHECK(two.record().stages[static_cast<std::size_t>(second)].cellSplit.empty());
}

}  // namespace
}  // namespace pr::raster
