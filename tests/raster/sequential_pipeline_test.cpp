// Tests of the sequential raster pipeline: the image does not depend on the region split
// (tiles, strips) or on the primitive processing order, bit for bit, and depth ties resolve by
// primitive order. These are the properties the parallel sort points rely on.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "common/parallel/runtime.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_point.h"
#include "raster/stages/depth_resolve.h"
#include "raster/raster_test_scenes.h"

namespace pr::raster {
namespace {

constexpr int kW = 80, kH = 60;

// A busy little scene: a textured floor, random triangles in front of the camera (some
// crossing the near plane, some double-sided, some interpenetrating), coplanar duplicates
// (exact depth ties), an emissive, a metal; a point, a spot and a directional light.
scene::Scene busyScene() {
  scene::Scene s = test::emptyScene();
  scene::Material red = s.materials[0];
  red.baseColorFactor = glm::vec4(0.9f, 0.1f, 0.1f, 1.0f);
  red.doubleSided = true;
  scene::Material metal = s.materials[0];
  metal.metallicFactor = 1.0f;
  metal.roughnessFactor = 0.3f;
  metal.baseColorFactor = glm::vec4(0.9f, 0.8f, 0.5f, 1.0f);
  scene::Material glow = s.materials[0];
  glow.emissiveFactor = glm::vec3(2.0f, 2.0f, 1.0f);
  scene::Material checker = s.materials[0];
  checker.baseColorTexture.texture = 0;
  scene::Material green = red;
  green.baseColorFactor = glm::vec4(0.1f, 0.9f, 0.1f, 1.0f);
  s.materials.insert(s.materials.end(), {red, metal, glow, checker, green});

  scene::Texture tex;
  tex.width = tex.height = 4;
  for (int i = 0; i < 16; ++i) {
    uint8_t v = ((i % 4) + (i / 4)) % 2 ? 230 : 40;
    tex.rgba8.insert(tex.rgba8.end(), {v, uint8_t(255 - v), 128, 255});
  }
  s.textures.push_back(tex);

  // Floor with UVs spanning several texture periods.
  uint32_t base = 0;
  for (int k = 0; k < 6; ++k) {
    for (int i = 0; i < 6; ++i) {
      glm::vec3 p(-6.0f + 2.0f * i, -1.5f, -12.0f + 2.5f * k);
      base = static_cast<uint32_t>(s.positions.size());
      s.positions.insert(s.positions.end(), {p, p + glm::vec3(0, 0, 2.5f), p + glm::vec3(2, 0, 2.5f), p + glm::vec3(2, 0, 0)});
      for (int c = 0; c < 4; ++c) s.uvs.push_back(glm::vec2(s.positions[base + c].x, s.positions[base + c].z) * 0.7f);
      s.triangles.push_back({{base, base + 1, base + 2}, 4});
      s.triangles.push_back({{base, base + 2, base + 3}, 4});
    }
  }
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 160; ++i) {
    glm::vec3 centre(3.0f * u(rng), 1.5f * u(rng), -6.0f + 5.5f * u(rng));  // some reach z > 0
    glm::vec3 a = centre + 1.5f * glm::vec3(u(rng), u(rng), u(rng));
    glm::vec3 b = centre + 1.5f * glm::vec3(u(rng), u(rng), u(rng));
    glm::vec3 c = centre + 1.5f * glm::vec3(u(rng), u(rng), u(rng));
    // Every 10th triangle twice, red then green (both double-sided): same fragments, same
    // depths, different colours.
    bool duplicated = i % 10 == 0;
    test::addTriangle(s, a, b, c, duplicated ? 1 : static_cast<uint32_t>(i % 4));
    if (duplicated) test::addTriangle(s, a, b, c, 5);
  }
  s.uvs.resize(s.positions.size(), glm::vec2(0.25f));
  scene::PunctualLight point, spot, sun;
  point.position = glm::vec3(1.0f, 2.0f, -3.0f);
  point.intensity = 20.0f;
  point.color = glm::vec3(1.0f, 0.9f, 0.8f);
  spot.type = scene::LightType::Spot;
  spot.position = glm::vec3(-2.0f, 3.0f, 0.0f);
  spot.direction = glm::normalize(glm::vec3(0.3f, -1.0f, -0.5f));
  spot.intensity = 40.0f;
  spot.innerConeAngle = 0.3f;
  spot.outerConeAngle = 0.6f;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(-0.2f, -1.0f, -0.3f));
  sun.intensity = 1.5f;
  s.lights = {point, spot, sun};
  return s;
}

// Inside the cloud of triangles: some cross the near plane and the camera plane.
scene::Camera busyCamera() { return test::lookAtCamera({0.5f, 0.3f, -1.0f}, {0.0f, -0.3f, -6.0f}, 1.0f, 0.05f); }

TEST_CASE("SequentialPipeline: region splits composite to the full-frame image bit for bit") {
  scene::Scene s = busyScene();
  RasterStats stats;
  RegionFramebuffer full = renderSequential(s, busyCamera(), kW, kH, {}, &stats);
  // The scene exercises what it is meant to: clipping, culling, most pixels covered.
  CHECK(stats.geometry.clipped > 0);
  CHECK(stats.geometry.culledBackFace > 0);
  CHECK(full.coveredPixels() > size_t(kW) * kH / 2);
  // Exact depth ties are visible: pixels won by the first of a duplicated pair.
  int ties = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      uint32_t p = keyPrimitive(full.key(x, y));
      ties += keyCovered(full.key(x, y)) && p + 1 < s.triangles.size() && s.triangles[p + 1].material == 5;
    }
  }
  CHECK(ties > 20);
  for (int tile : {1, 5, 8, 16, 64}) {
    SequentialOptions options;
    options.regions = tileRegions(kW, kH, tile);
    CAPTURE(tile);
    CHECK(identical(renderSequential(s, busyCamera(), kW, kH, options), full));
  }
  for (int strips : {2, 3, 7}) {
    SequentialOptions options;
    options.regions = stripRegions(kW, kH, strips);
    CAPTURE(strips);
    CHECK(identical(renderSequential(s, busyCamera(), kW, kH, options), full));
  }
  // The image handed to output holds the same colours.
  image::Image img = toImage(full);
  CHECK(img.width == kW);
  CHECK(img.height == kH);
  CHECK(img.at(kW / 2, kH / 3) == full.colour(kW / 2, kH / 3));
  // Uneven tiles offset from the block grid.
  SequentialOptions odd;
  odd.regions = {Rect{0, 0, 13, 60}, Rect{13, 0, 80, 29}, Rect{13, 29, 51, 60}, Rect{51, 29, 80, 60}};
  CHECK(identical(renderSequential(s, busyCamera(), kW, kH, odd), full));
}

TEST_CASE("SequentialPipeline: primitive order does not change the image") {
  scene::Scene s = busyScene();
  RegionFramebuffer reference = renderSequential(s, busyCamera(), kW, kH);
  FrameView view = makeFrameView(busyCamera(), kW, kH);
  ShadingContext ctx = makeShadingContext(s, view);
  const uint32_t n = static_cast<uint32_t>(s.triangles.size());

  // Batches of 7 processed last to first, triangles drawn in reverse.
  std::vector<ScreenTriangle> reversed;
  for (uint32_t end = n; end > 0;) {
    uint32_t first = end >= 7 ? end - 7 : 0;
    processTriangles(s, view, first, end - first, reversed);
    end = first;
  }
  std::reverse(reversed.begin(), reversed.end());
  RegionFramebuffer fb(Rect{0, 0, kW, kH});
  rasterizeTriangles(reversed, fb);
  shadeRegion(ctx, reversed, fb);
  CHECK(identical(fb, reference));

  // A shuffled order, drawn as two halves composited by depth (a sort-last-like merge).
  std::vector<ScreenTriangle> shuffled = reversed;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(99));
  size_t half = shuffled.size() / 2;
  std::vector<ScreenTriangle> first(shuffled.begin(), shuffled.begin() + half), second(shuffled.begin() + half, shuffled.end());
  RegionFramebuffer a(Rect{0, 0, kW, kH}), b(Rect{0, 0, kW, kH});
  rasterizeTriangles(first, a);
  shadeRegion(ctx, first, a);
  rasterizeTriangles(second, b);
  shadeRegion(ctx, second, b);
  RegionFramebuffer merged(Rect{0, 0, kW, kH});
  resolveInto(b, merged);
  resolveInto(a, merged);
  CHECK(identical(merged, reference));

  // Batch size changes nothing either.
  SequentialOptions small;
  small.batchSize = 3;
  CHECK(identical(renderSequential(s, busyCamera(), kW, kH, small), reference));
}

TEST_CASE("SequentialPipeline: exact depth ties go to the lower primitive id") {
  scene::Scene s = test::emptyScene();
  scene::Material green = s.materials[0];
  green.baseColorFactor = glm::vec4(0.0f, 1.0f, 0.0f, 1.0f);
  s.materials[0].baseColorFactor = glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
  s.materials.push_back(green);
  glm::vec3 a(-6, -6, -1), b(6, -6, -3), c(0, 6, -2);
  test::addTriangle(s, a, b, c, 0);  // red, primitive 0
  test::addTriangle(s, a, b, c, 1);  // green, primitive 1: the same fragments
  FrameView view = makeFrameView(test::pixelOrthoCamera(16), 16, 16);
  ShadingContext ctx = makeShadingContext(s, view);
  std::vector<ScreenTriangle> tris;
  processTriangles(s, view, 0, 2, tris);
  REQUIRE(tris.size() == 2);
  for (bool reverse : {false, true}) {
    if (reverse) std::reverse(tris.begin(), tris.end());
    RegionFramebuffer fb(Rect{0, 0, 16, 16});
    rasterizeTriangles(tris, fb);
    shadeRegion(ctx, tris, fb);
    int covered = 0, wrong = 0;
    for (int y = 0; y < 16; ++y) {
      for (int x = 0; x < 16; ++x) {
        if (!keyCovered(fb.key(x, y))) continue;
        ++covered;
        wrong += keyPrimitive(fb.key(x, y)) != 0 || fb.colour(x, y).y > fb.colour(x, y).x;
      }
    }
    CAPTURE(reverse);
    CHECK(covered > 50);
    CHECK(wrong == 0);
  }
}

TEST_CASE("SequentialRaster: the family's reference is the sequential pipeline, one task on PE 0, nothing sent") {
  const scene::Scene s = busyScene();
  const FrameView view = makeFrameView(busyCamera(), kW, kH);
  const RegionFramebuffer expected = renderSequential(s, view);
  for (const char* schedule : {"demand", "distributed"}) {
    CAPTURE(schedule);
    par::Runtime rt(3, schedule);
    std::unique_ptr<SortPoint> reference = makeSortPoint("sequential-raster");
    CHECK(identical(renderFrame(*reference, s, view, SortOptions{}, rt), expected));
    const par::RunRecord& record = rt.record();
    REQUIRE(record.stages.size() == 1);
    CHECK(record.stages[0].kind == par::kOnePeStage);
    CHECK(record.stages[0].channels.empty());
    REQUIRE(record.timeline.size() == 1);
    CHECK(record.timeline[0].pe == 0);
  }
}

}  // namespace
}  // namespace pr::raster
