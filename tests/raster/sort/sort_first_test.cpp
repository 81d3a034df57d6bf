// Sort-first: exact primitive routing on the hand-checked three-triangle scene, and frame
// coherence over a camera orbit (the previous frame's assignment is reused; only migrating
// primitives are sent; the images still match the sequential pipeline frame by frame).
#include <doctest/doctest.h>

#include <cmath>

#include "common/parallel/runtime.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_test_support.h"

namespace pr::raster {
namespace {

TEST_CASE("SortFirst: three triangles on two PEs route and count exactly") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "balanced");
  SortCounters c;
  RegionFramebuffer image = renderParallel(s, view, "sort-first", options, rt, &c);
  CHECK(identical(image, renderSequential(s, view)));
  // Contiguous start: PE 0 holds triangle 0, PE 1 holds 1 and 2. Triangle 0 stays on PE 0,
  // 1 stays on PE 1, 2 stays on PE 1 and is sent to PE 0 (a duplicate).
  CHECK(c.preTransforms == 3);
  CHECK(c.primitivesRouted == 4);
  CHECK(c.primitivesSent == 1);
  CHECK(c.primitivesDuplicated == 1);
  CHECK(c.primitivesMigrated == 0);
  CHECK(c.geometryRepeated == 4);  // PE 0 transforms {0, 2} again, PE 1 {1, 2}
  const test::StageTraffic sort = test::stageTraffic(rt.record(), "sort-first pre-transform");
  CHECK(sort.messagesSent == 1);
  CHECK(sort.bytesSent == sizeof(uint32_t));
  CHECK(sort.bytesReceived == sort.bytesSent);
}

TEST_CASE("SortFirst: a repeated frame reuses the assignment and sends nothing") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  SortCounters first, second;
  renderFrame(*sf, s, view, options, rt, &first);
  RegionFramebuffer again = renderFrame(*sf, s, view, options, rt, &second);
  CHECK(first.primitivesSent == 1);
  CHECK(second.primitivesSent == 0);
  CHECK(second.primitivesMigrated == 0);
  CHECK(identical(again, renderSequential(s, view)));
}

TEST_CASE("SortFirst: an orbit migrates primitives and every frame matches the sequential one") {
  const scene::Scene s = [] {
    scene::Scene t = test::emptyScene();
    // A ring of small triangles around the origin, so turning the camera moves them across strips.
    for (int i = 0; i < 24; ++i) {
      const float a = 6.2831853f * i / 24.0f;
      const glm::vec3 c(3.0f * std::cos(a), 0.0f, 3.0f * std::sin(a));
      test::addTriangle(t, c + glm::vec3(-0.3f, -0.3f, 0), c + glm::vec3(0.3f, -0.3f, 0), c + glm::vec3(0, 0.4f, 0));
    }
    for (auto& m : t.materials) m.doubleSided = true;
    return t;
  }();
  const scene::Camera start = test::lookAtCamera({0.0f, 4.0f, 9.0f}, {0.0f, 0.0f, 0.0f});
  SortOptions options;
  options.regions = RegionStrategy::StaticTiles;
  options.tileSizePx = 8;
  par::Runtime rt(3, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  uint64_t migrated = 0;
  for (int frame = 0; frame < 4; ++frame) {
    const scene::Camera cam = orbitCamera(start, glm::vec3(0.0f), 6.2831853f * frame / 16.0f);
    const FrameView view = makeFrameView(cam, 40, 32);
    SortCounters c;
    RegionFramebuffer image = renderFrame(*sf, s, view, options, rt, &c);
    CHECK(identical(image, renderSequential(s, view)));
    if (frame == 0) CHECK(c.primitivesMigrated == 0);
    else CHECK(c.primitivesMigrated == c.primitivesSent);  // after the first frame every send is a migration
    migrated += c.primitivesMigrated;
  }
  CHECK(migrated > 0);
}

}  // namespace
}  // namespace pr::raster
