// Tests of the rasterization stage on fixed-point screen triangles: watertightness (tessellated
// squares, fans), agreement with an exact inside test, degenerate and sub-pixel triangles,
// vertices on pixel centres and block boundaries, and region clipping.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "raster/framebuffer.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/setup.h"
#include "raster/raster_test_scenes.h"

namespace pr::raster {
namespace {

constexpr int kW = 96, kH = 72;
constexpr int kS = kSubpixelScale;

// Deterministic jitter in [-range, range] from an index (a simple integer hash).
int jitter(uint32_t i, int range) {
  uint32_t h = i * 2654435761u;
  h ^= h >> 15;
  h *= 2246822519u;
  h ^= h >> 13;
  return static_cast<int>(h % static_cast<uint32_t>(2 * range + 1)) - range;
}

// An n x n grid over the screen plus a margin, interior vertices jittered by up to `jit`
// sub-pixel units, each cell split along alternating diagonals.
std::vector<ScreenTriangle> tessellatedSquare(int n, int jit, int margin) {
  std::vector<glm::ivec2> v;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      int x = -margin * kS + static_cast<int>(int64_t(kW + 2 * margin) * kS * i / n);
      int y = -margin * kS + static_cast<int>(int64_t(kH + 2 * margin) * kS * j / n);
      bool interior = i > 0 && i < n && j > 0 && j < n;
      if (interior) {
        x += jitter(uint32_t(j * (n + 1) + i) * 2, jit);
        y += jitter(uint32_t(j * (n + 1) + i) * 2 + 1, jit);
      }
      v.emplace_back(x, y);
    }
  }
  std::vector<ScreenTriangle> tris;
  auto at = [&](int i, int j) { return v[size_t(j) * (n + 1) + i]; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      glm::ivec2 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      // Counter-clockwise as seen on screen = positive area (setup.h).
      if ((i + j) % 2 == 0) {
        tris.push_back(test::fixedTriangle(a, c, b));
        tris.push_back(test::fixedTriangle(a, d, c));
      } else {
        tris.push_back(test::fixedTriangle(a, d, b));
        tris.push_back(test::fixedTriangle(b, d, c));
      }
    }
  }
  return tris;
}

void requireExactlyOnce(const std::vector<int>& counts) {
  int zero = 0, many = 0;
  for (int c : counts) {
    zero += c == 0;
    many += c > 1;
  }
  CHECK(zero == 0);
  CHECK(many == 0);
}

TEST_CASE("Rasterize: a tessellated screen-filling square covers every pixel exactly once") {
  // Jittered vertices (arbitrary sub-pixel positions) and unjittered ones: with n = 12 the
  // grid lines fall on pixel centres and on 8-pixel block boundaries of the 96x72 screen.
  for (int jit : {0, 1, 37, 127}) {
    for (int n : {1, 12, 31}) {
      CAPTURE(jit);
      CAPTURE(n);
      auto tris = tessellatedSquare(n, jit, 0);
      requireExactlyOnce(test::coverageCounts(kW, kH, tris));
    }
  }
}

TEST_CASE("Rasterize: vertices exactly on pixel centres and block corners are covered once") {
  // Grid vertices at pixel centres (i + 1/2) of every 8th pixel and, separately, at integer
  // pixel corners on the 8x8 block grid: samples lie exactly on edges and vertices.
  for (int offset : {kS / 2, 0}) {
    std::vector<ScreenTriangle> tris;
    std::vector<glm::ivec2> v;
    const int step = 8 * kS;
    for (int y = -step + offset; y <= kH * kS + step; y += step) {
      for (int x = -step + offset; x <= kW * kS + step; x += step) v.emplace_back(x, y);
    }
    int cols = 0;
    for (int x = -step + offset; x <= kW * kS + step; x += step) ++cols;
    int rows = static_cast<int>(v.size()) / cols;
    for (int j = 0; j + 1 < rows; ++j) {
      for (int i = 0; i + 1 < cols; ++i) {
        glm::ivec2 a = v[j * cols + i], b = v[j * cols + i + 1], c = v[(j + 1) * cols + i + 1], d = v[(j + 1) * cols + i];
        tris.push_back(test::fixedTriangle(a, c, b));
        tris.push_back(test::fixedTriangle(a, d, c));
      }
    }
    CAPTURE(offset);
    requireExactlyOnce(test::coverageCounts(kW, kH, tris));
  }
}

TEST_CASE("Rasterize: fans around a shared vertex cover every pixel exactly once") {
  // Centre on a pixel centre, on a block corner, and at an odd sub-pixel position; the rim lies
  // far off screen so the fan covers the whole screen.
  const glm::ivec2 centres[] = {{40 * kS + kS / 2, 32 * kS + kS / 2}, {40 * kS, 32 * kS}, {40 * kS + 77, 31 * kS + 201}};
  for (glm::ivec2 c : centres) {
    for (int spokes : {3, 7, 16, 64}) {
      std::vector<glm::ivec2> rim;
      for (int k = 0; k < spokes; ++k) {
        double angle = 2.0 * 3.14159265358979 * k / spokes;
        rim.emplace_back(c.x + static_cast<int>(std::lround(4000.0 * kS * std::cos(angle))),
                         c.y + static_cast<int>(std::lround(4000.0 * kS * std::sin(angle))));
      }
      std::vector<ScreenTriangle> tris;
      for (int k = 0; k < spokes; ++k) tris.push_back(test::positiveTriangle(c, rim[k], rim[(k + 1) % spokes]));
      CAPTURE(spokes);
      requireExactlyOnce(test::coverageCounts(kW, kH, tris));
    }
  }
}

TEST_CASE("Rasterize: coverage agrees with an exact point-in-triangle test, blocks included") {
  // Samples strictly inside must be covered and samples strictly outside must not; samples on
  // an edge are the fill rule's business (tested above). Large triangles exercise block
  // acceptance and rejection, small ones the direct scan.
  for (uint32_t i = 0; i < 200; ++i) {
    int size = i % 2 ? 6 * kS : 200 * kS;
    glm::ivec2 p[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = glm::ivec2(kW * kS / 2 + jitter(i * 7 + k, size), kH * kS / 2 + jitter(i * 7 + 3 + k, size));
    }
    ScreenTriangle t = test::positiveTriangle(p[0], p[1], p[2]);
    TriangleSetup s;
    if (!setupTriangle(t, s)) continue;  // collinear
    auto counts = test::coverageCounts(kW, kH, {t});
    int wrong = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        // Exact: integer cross products at the sample (i + 1/2, j + 1/2) * 256.
        int64_t X = int64_t(x) * kS + kS / 2, Y = int64_t(y) * kS + kS / 2;
        int sign = 1;  // +1 strictly inside, -1 strictly outside, 0 on an edge
        for (int k = 0; k < 3; ++k) {
          int a = (k + 1) % 3, b = (k + 2) % 3;
          int64_t e = (int64_t(t.y[b]) - t.y[a]) * (X - t.x[a]) - (int64_t(t.x[b]) - t.x[a]) * (Y - t.y[a]);
          if (e < 0) sign = -1;
          else if (e == 0 && sign == 1) sign = 0;
        }
        int c = counts[size_t(y) * kW + x];
        if ((sign == 1 && c != 1) || (sign == -1 && c != 0)) ++wrong;
      }
    }
    CAPTURE(i);
    CHECK(wrong == 0);
  }
}

TEST_CASE("Rasterize: degenerate and sub-pixel triangles") {
  TriangleSetup s;
  // Zero area: a repeated vertex and three collinear vertices.
  CHECK_FALSE(setupTriangle(test::fixedTriangle({10 * kS, 10 * kS}, {10 * kS, 10 * kS}, {20 * kS, 5 * kS}), s));
  CHECK_FALSE(setupTriangle(test::fixedTriangle({0, 0}, {10 * kS, 10 * kS}, {20 * kS, 20 * kS}), s));
  // Negative area (wrong winding) is not drawn by setup either.
  CHECK(setupTriangle(test::fixedTriangle({0, 0}, {0, 10 * kS}, {10 * kS, 0}), s));
  CHECK_FALSE(setupTriangle(test::fixedTriangle({0, 0}, {10 * kS, 0}, {0, 10 * kS}), s));

  // A quarter-pixel triangle around the sample of pixel (5, 7): exactly that pixel.
  glm::ivec2 c(5 * kS + kS / 2, 7 * kS + kS / 2);
  auto one = test::coverageCounts(kW, kH, {test::positiveTriangle(c + glm::ivec2(-30, -20), c + glm::ivec2(40, -20), c + glm::ivec2(0, 30))});
  int total = 0;
  for (int v : one) total += v;
  CHECK(total == 1);
  CHECK(one[size_t(7) * kW + 5] == 1);

  // A sub-pixel triangle between samples covers nothing, and so does a one-unit sliver.
  glm::ivec2 corner(5 * kS + 10, 7 * kS + 10);
  auto none = test::coverageCounts(kW, kH, {test::positiveTriangle(corner, corner + glm::ivec2(60, 0), corner + glm::ivec2(0, 60)),
                                            test::positiveTriangle({0, 0}, {kW * kS, 1}, {0, 1})});
  total = 0;
  for (int v : none) total += v;
  CHECK(total == 0);
}

TEST_CASE("Rasterize: drawing region by region equals drawing the whole screen") {
  auto tris = tessellatedSquare(9, 90, 5);
  // Overlapping layers give depth tests something to resolve: a second, shifted grid in front.
  auto front = tessellatedSquare(5, 60, -20);
  for (auto& t : front) {
    for (float& d : t.depth) d = 0.25f;
  }
  tris.insert(tris.end(), front.begin(), front.end());
  for (uint32_t i = 0; i < tris.size(); ++i) tris[i].primitive = i;

  RegionFramebuffer full(Rect{0, 0, kW, kH});
  rasterizeTriangles(tris, full);
  CHECK(full.coveredPixels() == size_t(kW) * kH);
  for (int tile : {1, 7, 8, 64}) {
    for (const Rect& r : tileRegions(kW, kH, tile)) {
      RegionFramebuffer fb(r);
      rasterizeTriangles(tris, fb);
      bool same = true;
      for (int y = r.y0; y < r.y1; ++y) {
        for (int x = r.x0; x < r.x1; ++x) same &= fb.key(x, y) == full.key(x, y) && fb.triangle(x, y) == full.triangle(x, y);
      }
      CAPTURE(tile);
      REQUIRE(same);
    }
  }
}

}  // namespace
}  // namespace pr::raster
