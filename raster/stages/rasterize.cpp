// Rasterization into a RegionFramebuffer: coverage from forEachCoveredPixel, depth from the
// setup's depth plane evaluated per sample (never stepped in floating point, so the value of a
// pixel is the same whichever region or block it was reached from), z-test by fragment key.
// Runs on the PE that owns the framebuffer.
#include "raster/stages/rasterize.h"

#include "raster/framebuffer.h"
#include "common/scene/surface_material.h"
#include "common/util/hash.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {

RasterCounters& RasterCounters::operator+=(const RasterCounters& o) {
  trianglesSetUp += o.trianglesSetUp;
  fragments += o.fragments;
  fragmentsPassed += o.fragmentsPassed;
  return *this;
}

namespace {

// Whether the alpha-cut surface is there at the sample of pixel (x, y).
bool fragmentPasses(const scene::Scene& scene, const ScreenTriangle& tri, const TriangleSetup& s, int x, int y,
                    int64_t e1, int64_t e2) {
  const scene::Triangle& t = scene.triangles[tri.primitive];
  const glm::vec3 b = barycentricsFromEdges(tri, edgeAt(s, 0, x, y), e1, e2);
  glm::vec2 uv(0.0f);
  if (!scene.uvs.empty()) uv = b.x * scene.uvs[t.v[0]] + b.y * scene.uvs[t.v[1]] + b.z * scene.uvs[t.v[2]];
  glm::vec4 colour(1.0f);
  if (!scene.colors.empty()) colour = b.x * scene.colors[t.v[0]] + b.y * scene.colors[t.v[1]] + b.z * scene.colors[t.v[2]];
  const uint64_t h = mix64(mix64(0xb1e4d0a1fau ^ tri.primitive) ^ (uint64_t(uint32_t(x)) << 32 | uint32_t(y)));
  return scene::alphaPasses(scene.materials[t.material], scene::opacityAt(scene, t.material, uv, colour), unitFloat(h));
}

}  // namespace

void rasterizeTriangle(const ScreenTriangle& tri, uint32_t localIndex, const PixelWindow& fb,
                       RasterCounters* counters, const scene::Scene* alphaScene) {
  TriangleSetup s;
  if (!setupTriangle(tri, s)) return;
  const scene::Scene* alpha =
      alphaScene && scene::alphaCuts(alphaScene->materials[alphaScene->triangles[tri.primitive].material]) ? alphaScene
                                                                                                          : nullptr;
  const uint32_t order = primitiveOrder(tri.primitive, tri.sub);
  uint64_t* keys = fb.keys;
  uint32_t* triangles = fb.triangles;
  const Rect rect = fb.rect;
  const size_t stride = fb.stride;
  uint64_t fragments = 0, passed = 0;
  forEachCoveredPixel(s, rect, [&](int x, int y, int64_t e1, int64_t e2) {
    float depth = s.depth0 + float(e1) * s.depthE1 + float(e2) * s.depthE2;
    uint64_t key = fragmentKey(depth, order);
    size_t i = static_cast<size_t>(y - rect.y0) * stride + static_cast<size_t>(x - rect.x0);
    ++fragments;
    if (depthTest(keys[i], key) && (!alpha || fragmentPasses(*alpha, tri, s, x, y, e1, e2))) {
      keys[i] = key;
      triangles[i] = localIndex;
      ++passed;
    }
  });
  if (counters) {
    ++counters->trianglesSetUp;
    counters->fragments += fragments;
    counters->fragmentsPassed += passed;
  }
}

void rasterizeTriangles(std::span<const ScreenTriangle> tris, const PixelWindow& fb, RasterCounters* counters,
                        const scene::Scene* alphaScene) {
  for (size_t i = 0; i < tris.size(); ++i) rasterizeTriangle(tris[i], static_cast<uint32_t>(i), fb, counters, alphaScene);
}

}  // namespace pr::raster
