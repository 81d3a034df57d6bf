// Sort-last: full-frame compositing moves exactly the analytic volume — direct-send and
// binary-swap each send b * A * (1 - 1/P) bytes per PE, in P - 1 and log2 P messages — the
// sparse variant sends only the bounding rectangle of what a PE drew in each region, every
// stage's bytes sent equal bytes received, and a PE's buffer is cleared only where it held
// something without the next frame seeing any of it.
#include <doctest/doctest.h>

#include <bit>

#include "common/parallel/runtime.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "raster/frame_assembly.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_test_support.h"
#include "raster/stages/geometry.h"
#include "raster/stages/setup.h"

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
  const uint64_t perPeMessages =
      std::string(compositor) == "direct-send" ? uint64_t(pes - 1) : uint64_t(std::countr_zero(unsigned(pes)));
  // b A (1 - 1/P), and each message's two rectangles.
  const uint64_t perPeBytes = kPixelBytes * area * (pes - 1) / pes + perPeMessages * kPixelHeaderBytes;
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

TEST_CASE("SortLast: full-frame direct-send moves b*A*(1-1/P) pixel bytes in P-1 messages per PE") {
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

TEST_CASE("SortLast: full-frame binary-swap moves b*A*(1-1/P) pixel bytes in log2(P) messages per PE") {
  for (int pes : {1, 2, 4, 8}) checkAnalyticVolume("binary-swap", pes);
}

TEST_CASE("SortLast: sparse compositing sends the bounding rectangle of what the PE drew in each region") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  const Rect screen{0, 0, test::kTinySize, test::kTinySize};
  // PE 0 renders all three triangles (one batch of 4096): what it drew is the union of their
  // pixel bounds; PE 1 drew nothing, so it sends nothing.
  std::vector<ScreenTriangle> tris;
  processTriangles(s, view, 0, uint32_t(s.triangles.size()), tris);
  Rect drawn;
  for (const ScreenTriangle& t : tris) drawn = enclose(drawn, intersect(pixelBounds(t), screen));
  for (const char* compositor : {"direct-send", "binary-swap"}) {
    CAPTURE(compositor);
    SortOptions options;
    options.compositor = compositor;
    options.sparse = true;
    par::Runtime rt(2, "balanced");
    RegionFramebuffer image = renderParallel(s, view, "sort-last", options, rt);
    test::CounterTotals c = test::counterTotals(rt.record());
    CHECK(identical(image, renderSequential(s, view)));
    // Both compositors give PE 1 the lower half at P = 2.
    const Rect lower{0, test::kTinySize / 2, test::kTinySize, test::kTinySize};
    const Rect sent = intersect(lower, drawn);
    REQUIRE(sent.area() > 0);
    REQUIRE(sent.area() < lower.area());
    Rect covered;  // every covered pixel of the lower half lies in what was sent
    for (int y = lower.y0; y < lower.y1; ++y)
      for (int x = lower.x0; x < lower.x1; ++x)
        if (keyCovered(image.key(x, y))) covered = enclose(covered, Rect{x, y, x + 1, y + 1});
    CHECK(intersect(covered, sent) == covered);
    CHECK(c["Sort/pixels_sent"] == uint64_t(sent.area()));
    CHECK(c["Sort/composite_messages"] == 1);
    CHECK(c["Sort/composite_bytes"] == kPixelHeaderBytes + uint64_t(sent.area()) * kPixelBytes);
    const test::StageTraffic t = test::stageTraffic(rt.record(), compositor);
    CHECK(t.bytesSent == c["Sort/composite_bytes"]);
    CHECK(t.bytesReceived == t.bytesSent);
  }
}

TEST_CASE("SortLast: frames that cover different pixels leave nothing behind in the PEs' kept buffers") {
  const scene::Scene s = test::threeTriangles();
  const scene::Camera front = test::pixelOrthoCamera(test::kTinySize);
  // The camera moved 5 units to the right: the triangles move left, partly off the screen.
  scene::Camera right = front;
  right.cameraToWorld[3].x = 5.0f;
  const FrameView wide = makeFrameView(front, test::kTinySize, test::kTinySize);
  const FrameView narrow = makeFrameView(right, test::kTinySize, test::kTinySize);
  const RegionFramebuffer wideImage = renderSequential(s, wide), narrowImage = renderSequential(s, narrow);
  REQUIRE(wideImage.coveredPixels() > narrowImage.coveredPixels());
  REQUIRE(narrowImage.coveredPixels() > 0);
  size_t leftBehind = 0;  // covered in the wide frame, not in the narrow one
  for (int y = 0; y < test::kTinySize; ++y)
    for (int x = 0; x < test::kTinySize; ++x)
      leftBehind += keyCovered(wideImage.key(x, y)) && !keyCovered(narrowImage.key(x, y));
  REQUIRE(leftBehind > 0);
  for (const char* compositor : {"direct-send", "binary-swap"})
    for (bool sparse : {false, true})
      for (int pes : {1, 2, 4}) {
        CAPTURE(compositor);
        CAPTURE(sparse);
        CAPTURE(pes);
        SortOptions options;
        options.compositor = compositor;
        options.sparse = sparse;
        options.batchSize = 1;  // every PE draws some triangles
        par::Runtime rt(pes, "balanced");
        std::unique_ptr<SortPoint> sortPoint = makeSortPoint("sort-last");
        RegionFramebuffer image;
        for (int frame = 0; frame < 4; ++frame) {
          const bool isWide = frame % 2 == 0;
          renderFrame(*sortPoint, s, isWide ? wide : narrow, options, rt, image);
          CHECK(identical(image, isWide ? wideImage : narrowImage));
        }
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
