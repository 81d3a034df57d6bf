// Rasterization stage, shared by all pipelines: visits the pixels of one set-up triangle inside
// a rectangular screen region (a tile or strip the caller owns, or the whole screen in
// sort-last) with half-space edge functions stepped incrementally in exact integers, in 8x8
// blocks that are rejected or accepted whole by testing their corners. Coverage and the edge
// values handed to the visitor never depend on the region or the traversal order.
#pragma once

#include <cstdint>
#include <span>

#include "common/scene/scene.h"
#include "raster/framebuffer.h"
#include "raster/region.h"
#include "raster/stages/setup.h"

namespace pr::raster {

inline constexpr int kBlockSizePx = 8;

// Per-PE counts of the rasterization stage (Raster/...).
struct RasterCounters {
  uint64_t trianglesSetUp = 0;   // triangles with positive area that reached setup
  uint64_t fragments = 0;        // covered samples inside the region
  uint64_t fragmentsPassed = 0;  // fragments that won the depth test when drawn

  RasterCounters& operator+=(const RasterCounters& o);
};

namespace detail {

// Scans the pixels [x0, x1) x [y0, y1); kTest = false when the block is known to be inside.
template <bool kTest, class Visit>
inline void scanRect(const TriangleSetup& s, int x0, int y0, int x1, int y1, Visit& visit) {
  const int64_t sx = samplePosition(x0), sy = samplePosition(y0);
  // Biased values decide coverage; e1, e2 (unbiased) go to the visitor for interpolation.
  int64_t row0 = s.a[0] * sx + s.b[0] * sy + s.c[0] - s.bias[0];
  int64_t row1 = s.a[1] * sx + s.b[1] * sy + s.c[1];
  int64_t row2 = s.a[2] * sx + s.b[2] * sy + s.c[2];
  const int64_t dx0 = s.a[0] * kSubpixelScale, dx1 = s.a[1] * kSubpixelScale, dx2 = s.a[2] * kSubpixelScale;
  const int64_t dy0 = s.b[0] * kSubpixelScale, dy1 = s.b[1] * kSubpixelScale, dy2 = s.b[2] * kSubpixelScale;
  const int64_t bias1 = s.bias[1], bias2 = s.bias[2];
  for (int y = y0; y < y1; ++y) {
    int64_t e0 = row0, e1 = row1, e2 = row2;
    for (int x = x0; x < x1; ++x) {
      // All three non-negative <=> the OR of the biased values is non-negative.
      if (!kTest || (e0 | (e1 - bias1) | (e2 - bias2)) >= 0) visit(x, y, e1, e2);
      e0 += dx0;
      e1 += dx1;
      e2 += dx2;
    }
    row0 += dy0;
    row1 += dy1;
    row2 += dy2;
  }
}

}  // namespace detail

// Calls visit(x, y, e1, e2) once for every pixel of `region` whose sample the triangle covers
// under the top-left rule, with e1, e2 the unbiased edge values E_1, E_2 there. Inlined into
// each caller: no per-pixel indirect call.
template <class Visit>
void forEachCoveredPixel(const TriangleSetup& s, const Rect& region, Visit&& visit) {
  Rect r = intersect(s.bounds, region);
  if (r.empty()) return;
  // Small triangles (the common case in big meshes): one scan of the bounds.
  if (r.width() <= kBlockSizePx && r.height() <= kBlockSizePx) {
    detail::scanRect<true>(s, r.x0, r.y0, r.x1, r.y1, visit);
    return;
  }
  // Blocks aligned to the screen's 8x8 grid. Over a block the edge value is affine, so its
  // extremes are at corners: max < bias rejects, min >= bias accepts without per-pixel tests.
  constexpr int kMask = ~(kBlockSizePx - 1);
  for (int by = r.y0 & kMask; by < r.y1; by += kBlockSizePx) {
    int y0 = by < r.y0 ? r.y0 : by;
    int y1 = by + kBlockSizePx < r.y1 ? by + kBlockSizePx : r.y1;
    for (int bx = r.x0 & kMask; bx < r.x1; bx += kBlockSizePx) {
      int x0 = bx < r.x0 ? r.x0 : bx;
      int x1 = bx + kBlockSizePx < r.x1 ? bx + kBlockSizePx : r.x1;
      const int64_t spanX = int64_t(x1 - 1 - x0) * kSubpixelScale;
      const int64_t spanY = int64_t(y1 - 1 - y0) * kSubpixelScale;
      bool reject = false, accept = true;
      for (int k = 0; k < 3; ++k) {
        int64_t e = s.a[k] * samplePosition(x0) + s.b[k] * samplePosition(y0) + s.c[k] - s.bias[k];
        int64_t ax = s.a[k] * spanX, by2 = s.b[k] * spanY;
        int64_t maxE = e + (ax > 0 ? ax : 0) + (by2 > 0 ? by2 : 0);
        int64_t minE = e + (ax < 0 ? ax : 0) + (by2 < 0 ? by2 : 0);
        if (maxE < 0) reject = true;
        if (minE < 0) accept = false;
      }
      if (reject) continue;
      if (accept) detail::scanRect<false>(s, x0, y0, x1, y1, visit);
      else detail::scanRect<true>(s, x0, y0, x1, y1, visit);
    }
  }
}

// Rasterizes one triangle into the owner's pixels, clipped to the window's rectangle, with the
// depth test of depth_resolve.h; a winning fragment stores its key and localIndex (the
// triangle's position in the list the shade stage will read). Touches the window only.
// alphaScene, when given, is the scene whose alpha-cut materials (MASK, BLEND) drop fragments
// where the surface is not there (scene::alphaPasses); BLEND by stochastic transparency, its
// random number a hash of the pixel and the primitive, so every sort point, region split and P
// keep the same fragments. Only triangles of such materials pay for the test.
void rasterizeTriangle(const ScreenTriangle& tri, uint32_t localIndex, const PixelWindow& pixels,
                       RasterCounters* counters = nullptr, const scene::Scene* alphaScene = nullptr);

// All triangles of a list, localIndex = position in the list.
void rasterizeTriangles(std::span<const ScreenTriangle> tris, const PixelWindow& pixels,
                        RasterCounters* counters = nullptr, const scene::Scene* alphaScene = nullptr);

// The same into a whole framebuffer.
inline void rasterizeTriangle(const ScreenTriangle& tri, uint32_t localIndex, RegionFramebuffer& fb,
                              RasterCounters* counters = nullptr) {
  rasterizeTriangle(tri, localIndex, fb.window(), counters);
}
inline void rasterizeTriangles(std::span<const ScreenTriangle> tris, RegionFramebuffer& fb,
                               RasterCounters* counters = nullptr) {
  rasterizeTriangles(tris, fb.window(), counters);
}

}  // namespace pr::raster
