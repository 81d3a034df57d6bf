// Triangle setup: edge functions, fill rule, bounds and depth plane of one ScreenTriangle.
// Called by the rasterizing PE (a region owner, or a sort-last PE over the whole screen) for
// every triangle it draws, and by binning code through pixelBounds().
#include "raster/stages/setup.h"

#include <algorithm>

namespace pr::raster {

namespace {

// floor(v / 256) for any sign: arithmetic shift (C++20 defines >> on negatives).
int64_t floorSub(int64_t v) { return v >> kSubpixelBits; }

}  // namespace

namespace {

Rect pixelsBetween(int64_t minX, int64_t maxX, int64_t minY, int64_t maxY) {
  // Pixel i has its sample at 256 i + 128: the first with sample >= min is
  // ceil((min - 128) / 256), the last with sample <= max is floor((max - 128) / 256).
  constexpr int64_t kHalf = kSubpixelScale >> 1;
  Rect r;
  r.x0 = static_cast<int>(floorSub(minX - kHalf + kSubpixelScale - 1));
  r.x1 = static_cast<int>(floorSub(maxX - kHalf) + 1);
  r.y0 = static_cast<int>(floorSub(minY - kHalf + kSubpixelScale - 1));
  r.y1 = static_cast<int>(floorSub(maxY - kHalf) + 1);
  return r;
}

}  // namespace

Rect pixelBounds(const ScreenTriangle& t) {
  return pixelsBetween(std::min({t.x[0], t.x[1], t.x[2]}), std::max({t.x[0], t.x[1], t.x[2]}),
                       std::min({t.y[0], t.y[1], t.y[2]}), std::max({t.y[0], t.y[1], t.y[2]}));
}

Rect pixelBounds(std::span<const ScreenTriangle> tris) {
  if (tris.empty()) return Rect{};
  int32_t minX = tris[0].x[0], maxX = minX, minY = tris[0].y[0], maxY = minY;
  for (const ScreenTriangle& t : tris)
    for (int k = 0; k < 3; ++k) {
      minX = std::min(minX, t.x[k]);
      maxX = std::max(maxX, t.x[k]);
      minY = std::min(minY, t.y[k]);
      maxY = std::max(maxY, t.y[k]);
    }
  return pixelsBetween(minX, maxX, minY, maxY);
}

void edgeFunctions(const ScreenTriangle& t, EdgeFunctions& e) {
  for (int k = 0; k < 3; ++k) {
    int i = (k + 1) % 3, j = (k + 2) % 3;
    // E_k = (y_j - y_i)(X - x_i) - (x_j - x_i)(Y - y_i)
    e.a[k] = int64_t(t.y[j]) - t.y[i];
    e.b[k] = -(int64_t(t.x[j]) - t.x[i]);
    e.c[k] = -(e.a[k] * t.x[i] + e.b[k] * t.y[i]);
  }
}

bool setupTriangle(const ScreenTriangle& t, TriangleSetup& s) {
  edgeFunctions(t, s);
  for (int k = 0; k < 3; ++k) {
    // (a, b) is the inward normal; y grows downwards. Left edge: interior to the right (a > 0).
    // Top edge: horizontal (a == 0) with the interior below (b > 0).
    bool topLeft = s.a[k] > 0 || (s.a[k] == 0 && s.b[k] > 0);
    s.bias[k] = topLeft ? 0 : 1;
  }
  s.area2 = s.a[0] * t.x[0] + s.b[0] * t.y[0] + s.c[0];
  if (s.area2 <= 0) return false;
  s.bounds = pixelBounds(t);
  float invArea = 1.0f / float(s.area2);
  s.depth0 = t.depth[0];
  s.depthE1 = (t.depth[1] - t.depth[0]) * invArea;
  s.depthE2 = (t.depth[2] - t.depth[0]) * invArea;
  return true;
}

}  // namespace pr::raster
