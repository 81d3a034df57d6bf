// Triangle setup, between geometry and rasterization in every pipeline: the three half-space
// edge functions of a ScreenTriangle in exact 64-bit fixed-point arithmetic, the top-left fill
// rule folded into them, the pixel bounds that binning (sort-middle, sort-first) tests against
// screen regions, and the depth plane. Setup depends on the triangle only, never on the
// region being drawn, so every region owner computes the same values for the same pixel.
#pragma once

#include <cstdint>
#include <span>

#include "raster/region.h"
#include "raster/stages/geometry.h"

namespace pr::raster {

// Edge k joins the two vertices other than k. With X, Y the fixed-point sample position,
//   E_k(X, Y) = a[k] * X + b[k] * Y + c[k]
// is twice the signed area of (vertex k+1, vertex k+2, sample), positive inside, and
// E_0 + E_1 + E_2 = area2; E_k / area2 is the screen-space barycentric of vertex k.
// Magnitudes (geometry.h): |a|, |b| < 2^27.4 and |X|, |Y|, |x_i|, |y_i| < 2^26.4, so each
// product is below 2^53.8 and c, E below 2^56: exact.
struct EdgeFunctions {
  int64_t a[3], b[3], c[3];
};

// The edge functions alone (what shading needs to recover barycentrics at a pixel).
void edgeFunctions(const ScreenTriangle& tri, EdgeFunctions& edges);

struct TriangleSetup : EdgeFunctions {
  // Top-left rule: a sample exactly on edge k belongs to the triangle only when the edge is a
  // top edge (horizontal, interior below) or a left edge (interior to its right); bias[k] is 0
  // for those and 1 otherwise, and a sample is covered when E_k - bias[k] >= 0 for all k.
  // Two triangles sharing an edge see it with opposite orientation, so exactly one owns it.
  int64_t bias[3];
  int64_t area2;
  Rect bounds;  // pixels whose sample lies in the snapped bounding box (may extend off screen)
  // Depth at a sample: depth0 + E_1 * depthE1 + E_2 * depthE2 (affine in screen space).
  float depth0, depthE1, depthE2;
};

// False (nothing to draw) for a triangle with zero snapped area.
bool setupTriangle(const ScreenTriangle& tri, TriangleSetup& setup);

// The pixel bounds alone, for binning triangles to region owners.
Rect pixelBounds(const ScreenTriangle& tri);
// Pixel bounds that hold every triangle's of the list (those of its vertices' bounding box).
Rect pixelBounds(std::span<const ScreenTriangle> tris);

// Fixed-point sample position of pixel column/row i: its centre, i + 1/2.
inline int64_t samplePosition(int i) {
  return (int64_t(i) << kSubpixelBits) + (kSubpixelScale >> 1);
}

// Unbiased edge value E_k at the sample of pixel (x, y), as the rasterizer computed it
// incrementally (integer arithmetic is exact, so both agree bit for bit).
inline int64_t edgeAt(const EdgeFunctions& s, int k, int x, int y) {
  return s.a[k] * samplePosition(x) + s.b[k] * samplePosition(y) + s.c[k];
}

// Scene-triangle barycentrics (b0, b1, b2) from the exact edge values at a sample: the
// perspective-correct interpolation of shade.h (sceneBarycentrics), shared with the alpha
// test of the rasterization stage.
inline glm::vec3 barycentricsFromEdges(const ScreenTriangle& tri, int64_t e0, int64_t e1, int64_t e2) {
  float w0 = float(e0) * tri.invW[0];
  float w1 = float(e1) * tri.invW[1];
  float w2 = float(e2) * tri.invW[2];
  float inv = 1.0f / (w0 + w1 + w2);
  glm::vec2 b = (w0 * inv) * tri.bary[0] + (w1 * inv) * tri.bary[1] + (w2 * inv) * tri.bary[2];
  return glm::vec3(1.0f - b.x - b.y, b.x, b.y);
}

}  // namespace pr::raster
