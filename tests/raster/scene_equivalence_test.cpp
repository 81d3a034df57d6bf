// Equivalence of the sequential raster pipeline on real glTF content: the shared Khronos
// sample models and the bundled scenes render bit-identically whatever the region split and
// the primitive order, with finite colours. The parallel sort points will add their rows here.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "raster/sequential_pipeline.h"
#include "test_support.h"

namespace pr::raster {
namespace {

constexpr int kW = 64, kH = 48;

// Geometry in batches of 5 processed last to first, rasterized in reverse list order.
RegionFramebuffer renderReversed(const scene::Scene& s, const FrameView& view) {
  std::vector<ScreenTriangle> tris;
  const uint32_t n = static_cast<uint32_t>(s.triangles.size());
  for (uint32_t end = n; end > 0;) {
    uint32_t first = end >= 5 ? end - 5 : 0;
    processTriangles(s, view, first, end - first, tris);
    end = first;
  }
  std::reverse(tris.begin(), tris.end());
  RegionFramebuffer fb(Rect{0, 0, view.width, view.height});
  rasterizeTriangles(tris, fb);
  shadeRegion(makeShadingContext(s, view), tris, fb);
  return fb;
}

void checkScene(const std::filesystem::path& path) {
  CAPTURE(path.string());
  setQuiet(true);
  scene::Scene s = scene::loadGltf(path);
  FrameView view = makeFrameView(scene::selectCamera(s, "", float(kW) / kH), kW, kH);
  RegionFramebuffer full = renderSequential(s, view);
  CHECK(full.coveredPixels() > 0);
  int nonFinite = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      glm::vec3 c = full.colour(x, y);
      nonFinite += !(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
    }
  }
  CHECK(nonFinite == 0);
  SequentialOptions tiles, strips;
  tiles.regions = tileRegions(kW, kH, 8);
  strips.regions = stripRegions(kW, kH, 3);
  CHECK(identical(renderSequential(s, view, tiles), full));
  CHECK(identical(renderSequential(s, view, strips), full));
  CHECK(identical(renderReversed(s, view), full));
}

void checkSharedModels(std::initializer_list<const char*> models) {
  if (!test::haveSharedScenes()) return;
  for (const char* model : models) checkScene(test::sharedScenes() / model);
}

TEST_CASE("SceneEquivalence: shared models with plain geometry and cameras") {
  checkSharedModels({"Box/glTF/Box.gltf", "Cameras/glTF/Cameras.gltf", "OrientationTest/glTF-Binary/OrientationTest.glb",
                     "TriangleWithoutIndices/glTF-Embedded/TriangleWithoutIndices.gltf"});
}

TEST_CASE("SceneEquivalence: shared models with textures and mirroring") {
  checkSharedModels({"BoxTextured/glTF/BoxTextured.gltf", "Duck/glTF-Binary/Duck.glb", "Avocado/glTF/Avocado.gltf",
                     "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
                     "TextureTransformTest/glTF/TextureTransformTest.gltf"});
}

TEST_CASE("SceneEquivalence: shared models with punctual lights and emission") {
  checkSharedModels({"LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
                     "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb"});
}

TEST_CASE("SceneEquivalence: bundled scenes render identically across splits and orders") {
  checkScene(test::sourceDir() / "scenes" / "cornell.gltf");
  checkScene(test::sourceDir() / "scenes" / "hotspot.gltf");
}

}  // namespace
}  // namespace pr::raster
