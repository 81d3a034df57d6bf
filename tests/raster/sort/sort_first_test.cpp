// Sort-first: exact primitive routing on the hand-checked three-triangle scene, frame coherence
// over a camera orbit (the previous frame's assignment is reused; only primitives that reach a
// new owner are sent; the images still match the sequential pipeline frame by frame), and the
// migration counter: primitives whose owner set changed between frames, exactly.
#include <doctest/doctest.h>

#include <cmath>

#include "common/parallel/runtime.h"
#include "raster/frame_assembly.h"
#include "raster/parallel_pipeline.h"
#include "raster/scene_distribution.h"
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
  RegionFramebuffer image = renderParallel(s, view, "sort-first", options, rt);
  CHECK(identical(image, renderSequential(s, view)));
  // Contiguous start: PE 0 holds triangle 0, PE 1 holds 1 and 2. Triangle 0 stays on PE 0,
  // 1 stays on PE 1, 2 stays on PE 1 and is sent to PE 0 (a duplicate).
  test::CounterTotals c = test::counterTotals(rt.record());
  CHECK(c["Sort/pre_transforms"] == 3);
  CHECK(c["Sort/primitives_routed"] == 4);
  CHECK(c["Sort/primitives_sent"] == 1);
  CHECK(c["Sort/primitives_duplicated"] == 1);
  CHECK(c["Sort/primitives_migrated"] == 0);
  CHECK(c["Sort/geometry_repeated"] == 4);  // PE 0 transforms {0, 2} again, PE 1 {1, 2}
  // The one primitive sent travels as its data: id, index triple + material, and its three
  // vertices' position, normal, uv, colour and tangent.
  const test::StageTraffic sort = test::stageTraffic(rt.record(), "sort-first pre-transform");
  CHECK(sort.messagesSent == 1);
  CHECK(sort.bytesSent == kPrimitiveBytes);
  CHECK(kPrimitiveBytes == 212u);  // 4 + 16 + 3 * (12 + 12 + 8 + 16 + 16)
  CHECK(sort.bytesReceived == sort.bytesSent);
  // The initial distribution: PE 0 sends PE 1 its share {1, 2}, 2 primitives in one message.
  const test::StageTraffic distribute = test::stageTraffic(rt.record(), "sort-first distribute");
  CHECK(distribute.messagesSent == 1);
  CHECK(distribute.bytesSent == 2 * kPrimitiveBytes);
  // PE 1's finished strip (rows 8..15 of 16 x 16) goes to the assembler as one region message.
  const test::StageTraffic render = test::stageTraffic(rt.record(), "sort-first render");
  CHECK(render.messagesSent == 1);
  CHECK(render.bytesSent == kRegionHeaderBytes + 16 * 8 * kRegionPixelBytes);
}

TEST_CASE("SortFirst: a repeated frame reuses the assignment and sends no primitive") {
  const scene::Scene s = test::threeTriangles();
  const FrameView view = test::tinyView();
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  test::CounterTotals first = test::frameCounters(rt, [&] { renderFrame(*sf, s, view, options, rt); });
  RegionFramebuffer again;
  test::CounterTotals second = test::frameCounters(rt, [&] { again = renderFrame(*sf, s, view, options, rt); });
  CHECK(first["Sort/primitives_sent"] == 1);
  CHECK(second["Sort/primitives_sent"] == 0);
  CHECK(second["Sort/primitives_migrated"] == 0);
  CHECK(second["Scene/geometry_bytes_held"] == 0);  // the scene was distributed once, in frame 1
  CHECK(identical(again, renderSequential(s, view)));
}

TEST_CASE("SortFirst: a primitive off the screen is held but never drawn, and each frame pre-transforms it once") {
  // The three triangles plus one far left of the 16 x 16 screen (x in [-30, -26]): PE 1
  // (strips; contiguous start: PE 0 holds {0, 1}, PE 1 holds {2, 3}) keeps it unseen.
  scene::Scene s = test::threeTriangles();
  test::addTriangle(s, {-30, 6, 0}, {-30, 2, 0}, {-26, 6, 0});
  const FrameView view = test::tinyView();
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  for (int frame = 0; frame < 3; ++frame) {
    CAPTURE(frame);
    RegionFramebuffer image;
    test::CounterTotals c = test::frameCounters(rt, [&] { image = renderFrame(*sf, s, view, options, rt); });
    CHECK(identical(image, renderSequential(s, view)));
    // The 4 initial shares, then 5 held: triangle 2 overlaps both strips, so both owners hold it.
    CHECK(c["Sort/pre_transforms"] == (frame == 0 ? 4 : 5));
    CHECK(c["Sort/geometry_repeated"] == 4);  // the three on screen (2 twice), not the unseen one
    CHECK(c["Sort/primitives_routed"] == 4);
  }
}

// A ring of small triangles around the origin, so turning the camera moves them across regions.
scene::Scene ring() {
  scene::Scene t = test::emptyScene();
  for (int i = 0; i < 24; ++i) {
    const float a = 6.2831853f * i / 24.0f;
    const glm::vec3 c(3.0f * std::cos(a), 0.0f, 3.0f * std::sin(a));
    test::addTriangle(t, c + glm::vec3(-0.3f, -0.3f, 0), c + glm::vec3(0.3f, -0.3f, 0), c + glm::vec3(0, 0.4f, 0));
  }
  for (auto& m : t.materials) m.doubleSided = true;
  return t;
}

TEST_CASE("SortFirst: an orbit migrates primitives and every frame matches the sequential one") {
  const scene::Scene s = ring();
  const scene::Camera start = test::lookAtCamera({0.0f, 4.0f, 9.0f}, {0.0f, 0.0f, 0.0f});
  SortOptions options;
  options.regions = RegionStrategy::StaticTiles;
  options.tileSizePx = 8;
  par::Runtime rt(3, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  double migrated = 0;
  for (int frame = 0; frame < 4; ++frame) {
    CAPTURE(frame);
    const scene::Camera cam = orbitCamera(start, glm::vec3(0.0f), 6.2831853f * frame / 16.0f);
    const FrameView view = makeFrameView(cam, 40, 32);
    RegionFramebuffer image;
    test::CounterTotals c = test::frameCounters(rt, [&] { image = renderFrame(*sf, s, view, options, rt); });
    CHECK(identical(image, renderSequential(s, view)));
    // A migration is counted once per primitive, at most one per routed primitive.
    CHECK(c["Sort/primitives_migrated"] <= 24);
    if (frame == 0) CHECK(c["Sort/primitives_migrated"] == 0);
    migrated += c["Sort/primitives_migrated"];
  }
  CHECK(migrated > 0);
}

TEST_CASE("SortFirst: a static camera over several frames migrates nothing") {
  const scene::Scene s = ring();
  const FrameView view = makeFrameView(test::lookAtCamera({0.0f, 4.0f, 9.0f}, {0.0f, 0.0f, 0.0f}), 40, 32);
  SortOptions options;
  options.regions = RegionStrategy::StaticTiles;
  options.tileSizePx = 8;
  par::Runtime rt(3, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  for (int frame = 0; frame < 4; ++frame) {
    CAPTURE(frame);
    test::CounterTotals c = test::frameCounters(rt, [&] { renderFrame(*sf, s, view, options, rt); });
    CHECK(c["Sort/primitives_migrated"] == 0);
    if (frame == 0) CHECK(c["Sort/primitives_sent"] > 0);  // the first sort moves primitives
    else CHECK(c["Sort/primitives_sent"] == 0);
  }
}

TEST_CASE("SortFirst: a camera move that takes one triangle from the top strip to the bottom one is 1 migration") {
  // 16 x 16 through pixelOrthoCamera: pixel row j samples world y = camera y + 7.5 - j, so the
  // top strip (PE 0) is rows 0..7 and the bottom strip (PE 1) rows 8..15.
  //   A: y in [2, 5]   -> frame 1 rows 3..5 (top)       frame 2 rows 9..11 (bottom)
  //   B: y in [-4, -1] -> frame 1 rows 9..11 (bottom)   frame 2 rows 15..17, on screen row 15 (bottom)
  // Frame 2 raises the camera by 6 world units (every triangle 6 rows lower). Owner sets:
  // A {0} -> {1} changed, B {1} -> {1} unchanged: exactly 1 migration, and A is the one
  // primitive sent (PE 0, its primary, sends it to PE 1, which did not hold it).
  scene::Scene s = test::emptyScene();
  test::addTriangle(s, {-6, 5, 0}, {-6, 2, 0}, {-2, 5, 0});
  test::addTriangle(s, {2, -1, 0}, {2, -4, 0}, {6, -1, 0});
  const scene::Camera camera = test::pixelOrthoCamera(test::kTinySize);
  scene::Camera raised = camera;
  raised.cameraToWorld[3] = glm::vec4(0.0f, 6.0f, 10.0f, 1.0f);
  const FrameView before = makeFrameView(camera, test::kTinySize, test::kTinySize);
  const FrameView after = makeFrameView(raised, test::kTinySize, test::kTinySize);
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  par::Runtime rt(2, "balanced");
  std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
  // Frame 1: PE 0 holds A and owns it, PE 1 holds B and owns it: nothing moves.
  test::CounterTotals first = test::frameCounters(rt, [&] { renderFrame(*sf, s, before, options, rt); });
  CHECK(first["Sort/primitives_sent"] == 0);
  CHECK(first["Sort/primitives_migrated"] == 0);
  RegionFramebuffer image;
  test::CounterTotals second = test::frameCounters(rt, [&] { image = renderFrame(*sf, s, after, options, rt); });
  CHECK(second["Sort/primitives_migrated"] == 1);
  CHECK(second["Sort/primitives_sent"] == 1);
  CHECK(identical(image, renderSequential(s, after)));
  // A static third frame: nothing changes owner.
  test::CounterTotals third = test::frameCounters(rt, [&] { renderFrame(*sf, s, after, options, rt); });
  CHECK(third["Sort/primitives_migrated"] == 0);
}

TEST_CASE("SortFirst: with every PE's foreign geometry poisoned an orbit still gives the sequential frames") {
  // Each PE reads geometry (pre-transform, geometry again, deferred shading) from its own scene
  // copy, whose vertices of primitives it neither holds nor was sent are NaN and into which
  // what it receives is installed from the messages: any read of another PE's primitives
  // outside a counted message, or a message without the data, would change the frame.
  const scene::Scene s = ring();
  const scene::Camera start = test::lookAtCamera({0.0f, 4.0f, 9.0f}, {0.0f, 0.0f, 0.0f});
  for (RegionStrategy regions : {RegionStrategy::StaticTiles, RegionStrategy::StaticStrips, RegionStrategy::Dynamic}) {
    CAPTURE(regionStrategyName(regions));
    SortOptions options;
    options.regions = regions;
    options.tileSizePx = 8;
    options.poisonForeignGeometry = true;
    par::Runtime rt(3, "balanced");
    std::unique_ptr<SortPoint> sf = makeSortPoint("sort-first");
    for (int frame = 0; frame < 3; ++frame) {
      CAPTURE(frame);
      const scene::Camera cam = orbitCamera(start, glm::vec3(0.0f), 6.2831853f * frame / 16.0f);
      const FrameView view = makeFrameView(cam, 40, 32);
      CHECK(identical(renderFrame(*sf, s, view, options, rt), renderSequential(s, view)));
    }
  }
}

}  // namespace
}  // namespace pr::raster
