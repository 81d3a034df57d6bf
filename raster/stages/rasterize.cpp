// Rasterization into a RegionFramebuffer: coverage from forEachCoveredPixel, depth from the
// setup's depth plane evaluated per sample (never stepped in floating point, so the value of a
// pixel is the same whichever region or block it was reached from), z-test by fragment key.
// Runs on the PE that owns the framebuffer.
#include "raster/stages/rasterize.h"

#include "raster/framebuffer.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {

RasterCounters& RasterCounters::operator+=(const RasterCounters& o) {
  trianglesSetUp += o.trianglesSetUp;
  fragments += o.fragments;
  fragmentsPassed += o.fragmentsPassed;
  return *this;
}

void rasterizeTriangle(const ScreenTriangle& tri, uint32_t localIndex, const PixelWindow& fb,
                       RasterCounters* counters) {
  TriangleSetup s;
  if (!setupTriangle(tri, s)) return;
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
    if (depthTest(keys[i], key)) {
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

void rasterizeTriangles(std::span<const ScreenTriangle> tris, const PixelWindow& fb, RasterCounters* counters) {
  for (size_t i = 0; i < tris.size(); ++i) rasterizeTriangle(tris[i], static_cast<uint32_t>(i), fb, counters);
}

}  // namespace pr::raster
