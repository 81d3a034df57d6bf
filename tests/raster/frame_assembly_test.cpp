// FrameAssembly: results are transfers. Every sort point assembles the image on PE 0 from
// counted region messages (kind results): exact volumes on a 64 x 32 screen at P = 2, nonzero
// result traffic on the bundled Cornell box for every sort point, region assignment and
// compositor, and no bytes at all at P = 1 (the assembler stores its own regions in place).
#include <doctest/doctest.h>

#include <string>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "raster/frame_assembly.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_test_support.h"
#include "test_support.h"

namespace pr::raster {
namespace {

// 64 x 32 through pixelOrthoCamera (one world unit per pixel), the three-triangle scene.
constexpr int kW = 64, kH = 32;

// The stage in which each sort point's regions travel to the assembler.
std::string resultStage(const std::string& method) {
  if (method == "sort-first") return "sort-first render";
  if (method == "sort-middle") return "sort-middle rasterize";
  return "sort-last assemble";
}

struct Case {
  const char* method;
  const char* compositor;
};
constexpr Case kCases[] = {
    {"sort-first", "direct-send"}, {"sort-middle", "direct-send"}, {"sort-last", "direct-send"},
    {"sort-last", "binary-swap"}};

// What leaves a rank is the region's encoding: its size is what the record counts, and the
// decoded region holds the same keys and colours (no triangle indices); bad bytes are refused.
TEST_CASE("FrameAssembly: a region message decodes to the keys and colours it was made of, and is counted as its encoding") {
  RegionFramebuffer region(Rect{3, 5, 10, 9});
  for (int y = 5; y < 9; ++y)
    for (int x = 3; x < 10; ++x) {
      region.keys()[region.index(x, y)] = uint64_t(x * 100 + y);
      region.colours()[region.index(x, y)] = glm::vec3(float(x), float(y), 0.25f);
    }
  const par::Bytes bytes = par::encodeMessage(region);
  CHECK(bytes.size() == regionMessageBytes(region.rect()));
  CHECK(bytes.size() == kRegionHeaderBytes + 7 * 4 * kRegionPixelBytes);
  const RegionFramebuffer back = par::decodeMessage<RegionFramebuffer>(bytes);
  CHECK(identical(back, region));
  par::Bytes shortened(bytes.begin(), bytes.end() - 1);
  CHECK_THROWS_AS(par::decodeMessage<RegionFramebuffer>(shortened), par::WireError);
  par::Bytes longer = bytes;
  longer.push_back(std::byte{0});
  CHECK_THROWS_AS(par::decodeMessage<RegionFramebuffer>(longer), par::WireError);
}

// The assembler decodes another rank's region into storage from the sort point's pool, which
// store() gives back: the pool's buffer comes back holding the message's pixels, and the next
// region that arrives reuses it rather than growing the pool every frame.
TEST_CASE("FrameAssembly: a region from another rank is decoded into storage from the pool") {
  RegionFramebuffer region(Rect{0, 0, 16, 8});
  for (int i = 0; i < 16 * 8; ++i) {
    region.keys()[i] = uint64_t(i + 1);
    region.colours()[i] = glm::vec3(float(i), 0.5f, 1.0f);
  }
  const par::Bytes bytes = par::encodeMessage(region);
  RegionBufferPool pool;
  RegionFramebuffer storage(Rect{0, 0, 32, 32});
  const uint64_t* storageKeys = storage.keys();
  pool.give(std::move(storage));
  par::WireReader r(bytes);
  const RegionFramebuffer back = decodeRegion(r, &pool);
  CHECK(r.remaining() == 0);
  CHECK(identical(back, region));
  CHECK(back.keys() == storageKeys);  // the pool's storage, not a new buffer
  par::WireReader without(bytes);
  CHECK(identical(decodeRegion(without, nullptr), region));
}

TEST_CASE("FrameAssembly: at P = 2 on static strips PE 1's region is one message of header + 64*16 pixels") {
  // Strips: PE 0 rows 0..15, PE 1 rows 16..31. Sort-last composites the same strips with
  // direct-send; binary-swap cuts 64 x 32 across its longer side into two 32 x 32 halves, PE 1
  // keeping the right one: 1024 pixels either way. Bytes: 16-byte header + 1024 x (8-byte key
  // + 12-byte colour) = 20496.
  const scene::Scene s = test::threeTriangles();
  const FrameView view = makeFrameView(test::pixelOrthoCamera(kH), kW, kH);
  const uint64_t expected = kRegionHeaderBytes + 64 * 16 * kRegionPixelBytes;
  CHECK(expected == 20496u);
  for (const Case& c : kCases) {
    CAPTURE(c.method);
    CAPTURE(c.compositor);
    SortOptions options;
    options.regions = RegionStrategy::StaticStrips;
    options.compositor = c.compositor;
    par::Runtime rt(2, "balanced");
    CHECK(identical(renderParallel(s, view, c.method, options, rt), renderSequential(s, view)));
    const std::string stage = resultStage(c.method);
    const test::ChannelSum results = test::channelTraffic(rt.record(), "results");
    CHECK(results.messages == 1);
    CHECK(results.bytes == expected);
    CHECK(test::channelTraffic(rt.record(), "results", stage).bytes == expected);  // all in that stage
    const test::StageTraffic fromAssembler = test::stageTraffic(rt.record(), stage, kAssemblerPe);
    CHECK(fromAssembler.messagesReceived == 1);
    CHECK(fromAssembler.bytesReceived == expected);
    if (std::string(c.method) == "sort-last") CHECK(fromAssembler.messagesSent == 0);
  }
}

TEST_CASE("FrameAssembly: static tiles send every tile PE 1 owns, one message each") {
  // 16-pixel tiles: 4 x 2 tiles dealt round-robin, 4 to PE 1, each 16 + 256 x 20 bytes.
  const scene::Scene s = test::threeTriangles();
  const FrameView view = makeFrameView(test::pixelOrthoCamera(kH), kW, kH);
  for (const char* method : {"sort-first", "sort-middle"}) {
    CAPTURE(method);
    SortOptions options;
    options.regions = RegionStrategy::StaticTiles;
    options.tileSizePx = 16;
    par::Runtime rt(2, "balanced");
    CHECK(identical(renderParallel(s, view, method, options, rt), renderSequential(s, view)));
    const test::ChannelSum results = test::channelTraffic(rt.record(), "results");
    CHECK(results.messages == 4);
    CHECK(results.bytes == 4 * (kRegionHeaderBytes + 16 * 16 * kRegionPixelBytes));
  }
}

TEST_CASE("FrameAssembly: the Cornell box at P = 2 sends results for every sort point, P = 1 moves no bytes") {
  setQuiet(true);
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  const int w = 64, h = 48;
  const FrameView view = makeFrameView(scene::selectCamera(s, "", float(w) / h), w, h);
  const RegionFramebuffer reference = renderSequential(s, view);
  for (const test::SortRow& row : test::kSortRows) {
    CAPTURE(row.method);
    CAPTURE(regionStrategyName(row.regions));
    CAPTURE(row.compositor);
    CAPTURE(row.sparse);
    SortOptions options;
    options.regions = row.regions;
    options.tileSizePx = 16;
    options.batchSize = 64;
    options.compositor = row.compositor;
    options.sparse = row.sparse;
    for (int pes : {1, 2}) {
      CAPTURE(pes);
      par::Runtime rt(pes, "demand");
      CHECK(identical(renderParallel(s, view, row.method, options, rt), reference));
      const test::ChannelSum results = test::channelTraffic(rt.record(), "results");
      if (pes == 1) {
        CHECK(test::stageTraffic(rt.record(), "").bytesSent == 0);
        CHECK(test::stageTraffic(rt.record(), "").messagesSent == 0);
        CHECK(results.messages == 0);
        continue;
      }
      // Some region is drawn or composited by PE 1; its pixels are whole rows of rectangles.
      CHECK(results.messages > 0);
      const uint64_t pixelBytes = results.bytes - results.messages * kRegionHeaderBytes;
      CHECK(pixelBytes % kRegionPixelBytes == 0);
      CHECK(pixelBytes / kRegionPixelBytes > 0);
      CHECK(pixelBytes / kRegionPixelBytes < uint64_t(w) * h);  // the assembler draws some itself
      CHECK(test::stageTraffic(rt.record(), "", kAssemblerPe).messagesReceived >= results.messages);
    }
  }
}

}  // namespace
}  // namespace pr::raster
