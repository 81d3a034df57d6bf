// Sort-middle: exact triangle routing on the hand-checked three-triangle scene (2 PEs, static
// strips), the Channel volume it implies (triangles, and the finished regions sent to the
// assembler), and the image against the sequential pipeline.
#include <doctest/doctest.h>

#include "common/parallel/runtime.h"
#include "raster/frame_assembly.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_test_support.h"

namespace pr::raster {
namespace {

TEST_CASE("SortMiddle: three triangles on two PEs route and count exactly") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  options.batchSize = 1;  // one geometry task per triangle
  // balanced: PE 0 transforms triangles 0 and 1, PE 1 triangle 2.
  par::Runtime rt(2, "balanced");
  RegionFramebuffer image = renderParallel(s, view, "sort-middle", options, rt);
  CHECK(identical(image, renderSequential(s, view)));
  // Triangle 0 -> owner 0 (kept), 1 -> owner 1 (sent), 2 -> owners 0 (sent) and 1 (kept).
  test::CounterTotals c = test::counterTotals(rt.record());
  CHECK(c["Sort/triangles_routed"] == 4);
  CHECK(c["Sort/triangles_sent"] == 2);
  CHECK(c["Sort/triangles_duplicated"] == 1);
  const test::StageTraffic geometry = test::stageTraffic(rt.record(), "sort-middle geometry");
  CHECK(geometry.messagesSent == 2);  // PE 0 -> PE 1 and PE 1 -> PE 0, one message each
  CHECK(geometry.bytesSent == 2 * sizeof(ScreenTriangle));
  CHECK(geometry.bytesReceived == geometry.bytesSent);
  // Rasterizing moves only the result: PE 1's strip (rows 8..15 of 16 x 16) to the assembler.
  const test::StageTraffic raster = test::stageTraffic(rt.record(), "sort-middle rasterize");
  CHECK(raster.messagesSent == 1);
  CHECK(raster.bytesSent == kRegionHeaderBytes + 16 * 8 * kRegionPixelBytes);
  CHECK(test::channelTraffic(rt.record(), "results").bytes == raster.bytesSent);
}

TEST_CASE("SortMiddle: one PE sends nothing to another PE") {
  const scene::Scene s = test::threeTriangles();
  par::Runtime rt(1, "balanced");
  renderParallel(s, test::tinyView(), "sort-middle", SortOptions{}, rt);
  CHECK(test::counterTotal(rt.record(), "Sort/triangles_routed") == 3);
  CHECK(test::counterTotal(rt.record(), "Sort/triangles_sent") == 0);
  CHECK(test::stageTraffic(rt.record(), "").bytesSent == 0);
}

TEST_CASE("SortMiddle: dynamic tiles pull every tile's triangles from every PE") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions options;
  options.regions = RegionStrategy::Dynamic;
  options.tileSizePx = 8;  // four 8x8 tiles
  options.batchSize = 1;
  par::Runtime rt(2, "demand");
  RegionFramebuffer image = renderParallel(s, view, "sort-middle", options, rt);
  CHECK(identical(image, renderSequential(s, view)));
  // Triangle 0 overlaps tile 0 only, triangle 1 tile 2 only, triangle 2 tiles 1 and 3.
  test::CounterTotals c = test::counterTotals(rt.record());
  CHECK(c["Sort/triangles_routed"] == 4);
  CHECK(c["Sort/triangles_duplicated"] == 1);
  // Whoever takes a tile asks the other PE once and gets one reply (possibly empty): 4 tiles
  // x (1 request + 1 reply) messages; reply bytes are the triangles that changed PE. Each tile
  // PE 1 drew goes to the assembler: one 8 x 8 region message each.
  const test::StageTraffic raster = test::stageTraffic(rt.record(), "sort-middle rasterize");
  const test::ChannelSum results = test::channelTraffic(rt.record(), "results");
  CHECK(results.bytes == results.messages * (kRegionHeaderBytes + 64 * kRegionPixelBytes));
  CHECK(raster.messagesSent == 8 + results.messages);
  CHECK(raster.bytesSent == 4 * 8 + uint64_t(c["Sort/triangles_sent"]) * sizeof(ScreenTriangle) + results.bytes);
  CHECK(raster.bytesReceived == raster.bytesSent);
}

}  // namespace
}  // namespace pr::raster
