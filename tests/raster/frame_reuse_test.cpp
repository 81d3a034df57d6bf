// One image reused from frame to frame (what an animation and the benchmark do): every sort
// point must write every pixel of the frame, whatever the image held before, through both the
// per-PE scratch tile (small regions) and in-place drawing (regions above kScratchTilePixels).
#include <doctest/doctest.h>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/bins.h"
#include "test_support.h"

namespace pr::raster {
namespace {

TEST_CASE("FrameReuse: a second frame into the same image equals a fresh render of it") {
  const scene::Scene s = scene::loadGltf((test::sourceDir() / "scenes" / "cornell.gltf").string());
  const scene::Camera camera = scene::selectCamera(s, "", 256.0f / 160.0f);
  const FrameView first = makeFrameView(camera, 256, 160);
  const FrameView second = makeFrameView(orbitCamera(camera, s.bounds.center(), 0.7f), 256, 160);
  const RegionFramebuffer expected = renderSequential(s, second);
  REQUIRE(!identical(renderSequential(s, first), expected));
  // Two static strips of 256 x 80 pixels are drawn in place, 32-pixel tiles in the scratch tile.
  REQUIRE(256 * 80 > kScratchTilePixels);
  for (const SortPointInfo& info : sortPoints()) {
    for (RegionStrategy regions : {RegionStrategy::StaticStrips, RegionStrategy::StaticTiles, RegionStrategy::Dynamic}) {
      CAPTURE(info.name);
      CAPTURE(regionStrategyName(regions));
      SortOptions options;
      options.regions = regions;
      par::Runtime rt(2);
      std::unique_ptr<SortPoint> sortPoint = info.make();
      RegionFramebuffer image;
      renderFrame(*sortPoint, s, first, options, rt, image);
      renderFrame(*sortPoint, s, second, options, rt, image);
      CHECK(identical(image, expected));
      // A different size reallocates the image; the sort point's kept buffers follow.
      const FrameView small = makeFrameView(camera, 96, 64);
      renderFrame(*sortPoint, s, small, options, rt, image);
      CHECK(identical(image, renderSequential(s, small)));
    }
  }
}

TEST_CASE("FrameReuse: the sequential pipeline into a reused image") {
  const scene::Scene s = scene::loadGltf((test::sourceDir() / "scenes" / "cornell.gltf").string());
  const scene::Camera camera = scene::selectCamera(s, "", 1.5f);
  const FrameView first = makeFrameView(camera, 120, 80);
  const FrameView second = makeFrameView(orbitCamera(camera, s.bounds.center(), -0.5f), 120, 80);
  SequentialOptions tiles;
  tiles.regions = tileRegions(120, 80, 16);
  RegionFramebuffer image;
  renderSequential(s, first, {}, image);
  renderSequential(s, second, tiles, image);
  CHECK(identical(image, renderSequential(s, second)));
}

}  // namespace
}  // namespace pr::raster
