// Sort-last: full-frame compositing moves exactly the analytic volume — direct-send and
// binary-swap each send b * A * (1 - 1/P) bytes per PE, in P - 1 and log2 P messages — the
// sparse variant sends only covered pixels, and every stage's bytes sent equal bytes received.
#include <doctest/doctest.h>

#include <bit>

#include "common/parallel/runtime.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "raster/frame_assembly.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_test_support.h"

namespace pr::raster {
namespace {

// 64 x 32 pixels: A = 2048 splits exactly into P strips and into binary-swap halves for
// P = 2, 4, 8 (halves 32x32, 32x16, 16x16).
constexpr int kW = 64, kH = 32;

void checkAnalyticVolume(const char* compositor, int pes) {
  CAPTURE(compositor);
  CAPTURE(pes);
  const scene::Scene s = test::threeTriangles();
  const FrameView view = makeFrameView(test::pixelOrthoCamera(kH), kW, kH);
  SortOptions options;
  options.compositor = compositor;
  par::Runtime rt(pes, "balanced");
  RegionFramebuffer image = renderParallel(s, view, "sort-last", options, rt);
  CHECK(identical(image, renderSequential(s, view)));
  test::CounterTotals c = test::counterTotals(rt.record());
  const uint64_t area = uint64_t(kW) * kH;
  const uint64_t perPeBytes = kFullPixelBytes * area * (pes - 1) / pes;  // b A (1 - 1/P)
  const uint64_t perPeMessages =
      std::string(compositor) == "direct-send" ? uint64_t(pes - 1) : uint64_t(std::countr_zero(unsigned(pes)));
  for (int p = 0; p < pes; ++p) {
    CAPTURE(p);
    const test::StageTraffic t = test::stageTraffic(rt.record(), compositor, p);
    CHECK(t.bytesSent == perPeBytes);
    CHECK(t.messagesSent == perPeMessages);
    CHECK(t.bytesReceived == perPeBytes);
  }
  CHECK(c["Sort/composite_bytes"] == perPeBytes * pes);
  CHECK(c["Sort/pixels_sent"] == area * (pes - 1));
  // Rendering itself moves nothing: each PE draws into its own buffer.
  CHECK(test::stageTraffic(rt.record(), "sort-last clear").bytesSent == 0);
  CHECK(test::stageTraffic(rt.record(), "sort-last render").bytesSent == 0);
  CHECK(test::stageTraffic(rt.record(), "sort-last shade").bytesSent == 0);
  // Assembly: every PE but the assembler sends its composited 1/P of the screen, one message.
  const test::StageTraffic assemble = test::stageTraffic(rt.record(), "sort-last assemble");
  CHECK(assemble.messagesSent == uint64_t(pes - 1));
  CHECK(assemble.bytesSent == uint64_t(pes - 1) * (kRegionHeaderBytes + area / pes * kRegionPixelBytes));
}

TEST_CASE("SortLast: full-frame direct-send moves b*A*(1-1/P) bytes in P-1 messages per PE") {
  for (int pes : {1, 2, 3, 4, 8}) {
    if (pes == 3) {
      // 32 rows in 3 strips are not equal: check the totals instead (every other PE's strip).
      const scene::Scene s = test::threeTriangles();
      const FrameView view = makeFrameView(test::pixelOrthoCamera(kH), kW, kH);
      par::Runtime rt(3, "balanced");
      renderParallel(s, view, "sort-last", SortOptions{}, rt);
      CHECK(test::counterTotal(rt.record(), "Sort/pixels_sent") == uint64_t(kW) * kH * 2);
      CHECK(test::counterTotal(rt.record(), "Sort/composite_messages") == 6);
      // Strips of 10, 11 and 11 rows (stripRegions): PEs 1 and 2 send theirs to PE 0.
      CHECK(test::channelTraffic(rt.record(), "results").bytes ==
            2 * kRegionHeaderBytes + uint64_t(kW) * (11 + 11) * kRegionPixelBytes);
      continue;
    }
    checkAnalyticVolume("direct-send", pes);
  }
}

TEST_CASE("SortLast: full-frame binary-swap moves b*A*(1-1/P) bytes in log2(P) messages per PE") {
  for (int pes : {1, 2, 4, 8}) checkAnalyticVolume("binary-swap", pes);
}

TEST_CASE("SortLast: sparse compositing sends only covered pixels, with their index") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  for (const char* compositor : {"direct-send", "binary-swap"}) {
    CAPTURE(compositor);
    SortOptions options;
    options.compositor = compositor;
    options.sparse = true;
    par::Runtime rt(2, "balanced");
    RegionFramebuffer image = renderParallel(s, view, "sort-last", options, rt);
    test::CounterTotals c = test::counterTotals(rt.record());
    CHECK(identical(image, renderSequential(s, view)));
    // batchSize 4096: PE 0 renders all three triangles and PE 1 none, so PE 0 sends its
    // covered pixels of PE 1's half and PE 1 sends nothing.
    const size_t coveredInLower = [&] {
      size_t n = 0;
      for (int y = test::kTinySize / 2; y < test::kTinySize; ++y)
        for (int x = 0; x < test::kTinySize; ++x) n += keyCovered(image.key(x, y));
      return n;
    }();
    CHECK(coveredInLower > 0);
    CHECK(c["Sort/pixels_sent"] == coveredInLower);
    CHECK(c["Sort/composite_messages"] == 1);
    CHECK(c["Sort/composite_bytes"] == coveredInLower * kSparsePixelBytes);
    const test::StageTraffic t = test::stageTraffic(rt.record(), compositor);
    CHECK(t.bytesSent == c["Sort/composite_bytes"]);
    CHECK(t.bytesReceived == t.bytesSent);
  }
}

TEST_CASE("SortLast: binary-swap on a PE count that is not a power of two is an input error") {
  const scene::Scene s = test::threeTriangles();
  SortOptions options;
  options.compositor = "binary-swap";
  par::Runtime rt(3, "balanced");
  CHECK_THROWS_WITH_AS(renderParallel(s, test::tinyView(), "sort-last", options, rt),
                       doctest::Contains("power-of-two"), InputError);
  options.compositor = "tree";
  CHECK_THROWS_WITH_AS(renderParallel(s, test::tinyView(), "sort-last", options, rt),
                       doctest::Contains("unknown compositor 'tree'"), InputError);
}

}  // namespace
}  // namespace pr::raster
