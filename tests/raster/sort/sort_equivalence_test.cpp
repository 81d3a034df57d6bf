// SortEquivalence: the equivalence table of the parallel raster pipelines. Every sort point,
// for every P in {1, 2, 3, 4, 7, 8}, every region assignment and (sort-last) every compositor
// in full and sparse form, renders bit-identically to the sequential pipeline, on the bundled
// scenes and the shared glTF models; and every stage's bytes sent equal its bytes received.
#include <doctest/doctest.h>

#include <bit>
#include <optional>
#include <string>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_test_support.h"
#include "test_support.h"

namespace pr::raster {
namespace {

constexpr int kW = 64, kH = 48;

// Bit-identical rows (test::kSortRows): the depth key decides every pixel from the set of its
// fragments alone (depth_resolve.h), and shading depends only on (triangle, pixel), so no row
// has a tolerance.

// only / strategy: run the rows of this method and region assignment alone (empty: all), to
// keep big scenes under a second per test case.
void checkScene(const scene::Scene& s, const FrameView& view, const std::string& only = "", std::optional<RegionStrategy> strategy = {}) {
  const RegionFramebuffer reference = renderSequential(s, view);
  for (int pes : {1, 2, 3, 4, 7, 8}) {
    // Small batches and tiles so that every PE gets primitives and regions.
    const uint32_t batch = std::max<uint32_t>(1, uint32_t(s.triangles.size() / (2 * pes) + 1));
    for (const test::SortRow& row : test::kSortRows) {
      if (!only.empty() && only != row.method) continue;
      if (strategy && row.regions != *strategy) continue;
      if (std::string(row.compositor) == "binary-swap" && !std::has_single_bit(unsigned(pes))) continue;
      CAPTURE(pes);
      CAPTURE(row.method);
      CAPTURE(regionStrategyName(row.regions));
      CAPTURE(row.compositor);
      CAPTURE(row.sparse);
      SortOptions options;
      options.regions = row.regions;
      options.tileSizePx = 16;
      options.batchSize = batch;
      options.compositor = row.compositor;
      options.sparse = row.sparse;
      par::Runtime rt(pes, "demand");
      CHECK(identical(renderParallel(s, view, row.method, options, rt), reference));
      for (const par::StageRecord& stage : rt.record().stages) {
        const test::StageTraffic t = test::stageTraffic(rt.record(), stage.name);
        CHECK(t.bytesSent == t.bytesReceived);
        CHECK(t.messagesSent == t.messagesReceived);
        if (pes == 1) CHECK(t.bytesSent == 0);
      }
    }
  }
}

void checkFile(const std::filesystem::path& path, const std::string& only = "", std::optional<RegionStrategy> strategy = {}) {
  CAPTURE(path.string());
  setQuiet(true);
  const scene::Scene s = scene::loadGltf(path);
  checkScene(s, makeFrameView(scene::selectCamera(s, "", float(kW) / kH), kW, kH), only, strategy);
}

TEST_CASE("SortEquivalence: bundled Cornell boxes") {
  checkFile(test::sourceDir() / "scenes" / "cornell.gltf");
  checkFile(test::sourceDir() / "scenes" / "cornell-diffuse.gltf");
}

// The hot-spot scene has 177k triangles: one test case per sort point.
TEST_CASE("SortEquivalence: bundled hot-spot scene, sort-first static strips") {
  checkFile(test::sourceDir() / "scenes" / "hotspot.gltf", "sort-first", RegionStrategy::StaticStrips);
}

TEST_CASE("SortEquivalence: bundled hot-spot scene, sort-first static tiles") {
  checkFile(test::sourceDir() / "scenes" / "hotspot.gltf", "sort-first", RegionStrategy::StaticTiles);
}

TEST_CASE("SortEquivalence: bundled hot-spot scene, sort-first dynamic") {
  checkFile(test::sourceDir() / "scenes" / "hotspot.gltf", "sort-first", RegionStrategy::Dynamic);
}

TEST_CASE("SortEquivalence: bundled hot-spot scene, sort-middle") {
  checkFile(test::sourceDir() / "scenes" / "hotspot.gltf", "sort-middle");
}

TEST_CASE("SortEquivalence: bundled hot-spot scene, sort-last") {
  checkFile(test::sourceDir() / "scenes" / "hotspot.gltf", "sort-last");
}

TEST_CASE("SortEquivalence: shared models with plain geometry and textures") {
  if (!test::haveSharedScenes()) return;
  for (const char* m : {"Box/glTF/Box.gltf", "BoxTextured/glTF/BoxTextured.gltf", "Duck/glTF-Binary/Duck.glb"})
    checkFile(test::sharedScenes() / m);
}

TEST_CASE("SortEquivalence: shared models with mirroring and emission") {
  if (!test::haveSharedScenes()) return;
  for (const char* m : {"NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
                        "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb"})
    checkFile(test::sharedScenes() / m);
}

TEST_CASE("SortEquivalence: shared model with punctual lights") {
  if (!test::haveSharedScenes()) return;
  checkFile(test::sharedScenes() / "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf");
}

TEST_CASE("SortEquivalence: a near-plane-crossing triangle and a huge one") {
  scene::Scene s = test::emptyScene();
  test::addTriangle(s, {-2, -1, 5}, {2, -1, -3}, {0, 1, -3});          // crosses the camera plane
  test::addTriangle(s, {-1e4f, -1e4f, -8}, {1e4f, -1e4f, -8}, {0, 1e4f, -8});  // far beyond the screen
  for (auto& m : s.materials) m.doubleSided = true;
  const scene::Camera cam = test::lookAtCamera({0, 0, 1}, {0, 0, -1});
  checkScene(s, makeFrameView(cam, kW, kH));
}

TEST_CASE("SortEquivalence: a screen with fewer rows and columns than PEs") {
  // 5 x 3 pixels: strips and compositing regions run out before the PEs do, and binary-swap
  // halves become empty; every PE still takes part and the image is unchanged.
  scene::Scene s = test::threeTriangles();
  test::addTriangle(s, {-1.5f, -1.5f, 0.5f}, {1.5f, -1.5f, 0.5f}, {0.0f, 1.5f, 0.5f});
  const FrameView view = makeFrameView(test::pixelOrthoCamera(4), 5, 3);
  REQUIRE(renderSequential(s, view).coveredPixels() > 0);
  checkScene(s, view);
}

}  // namespace
}  // namespace pr::raster
