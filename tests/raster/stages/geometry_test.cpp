// Tests of the geometry stage: back-face culling and double-sided materials, near-plane and
// camera-plane (w <= 0) clipping checked against ray casting, watertightness of a floor cut
// by the near plane, huge triangles (guard band), extreme depth ranges, exact snapping.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/util/error.h"
#include "raster/framebuffer.h"
#include "raster/stages/depth_resolve.h"
#include "raster/stages/geometry.h"
#include "raster/stages/rasterize.h"
#include "raster/raster_test_scenes.h"

namespace pr::raster {
namespace {

std::vector<ScreenTriangle> geometry(const scene::Scene& s, const FrameView& view, GeometryCounters* c = nullptr) {
  std::vector<ScreenTriangle> out;
  processTriangles(s, view, 0, static_cast<uint32_t>(s.triangles.size()), out, c);
  return out;
}

bool allFinite(const std::vector<ScreenTriangle>& tris) {
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(t.depth[k]) || !std::isfinite(t.invW[k]) || !(t.invW[k] > 0.0f) ||
          !std::isfinite(t.bary[k].x) || !std::isfinite(t.bary[k].y)) {
        return false;
      }
    }
  }
  return true;
}

// Direction of the ray through the sample of pixel (i, j) of the lookAtCamera at the origin
// looking down -z (camera space = world space).
glm::dvec3 pixelRay(int i, int j, int width, int height, double yfov) {
  double t = std::tan(yfov / 2.0);
  double aspect = double(width) / height;
  double x = ((i + 0.5) / width * 2.0 - 1.0) * t * aspect;
  double y = (1.0 - (j + 0.5) / height * 2.0) * t;
  return glm::dvec3(x, y, -1.0);
}

TEST_CASE("Geometry: back faces are culled unless the material is double-sided") {
  scene::Scene s = test::emptyScene();
  scene::Material twoSided = s.materials[0];
  twoSided.doubleSided = true;
  s.materials.push_back(twoSided);
  // Counter-clockwise seen from the camera at +z: a front face.
  glm::vec3 a(-10.0f, -10.0f, 0.0f), b(10.0f, -10.0f, 0.0f), c(0.0f, 10.0f, 0.0f);
  test::addTriangle(s, a, b, c, 0);
  test::addTriangle(s, a, c, b, 0);  // back face, single-sided: culled
  test::addTriangle(s, a, c, b, 1);  // back face, double-sided: drawn, flagged
  FrameView view = makeFrameView(test::pixelOrthoCamera(32), 32, 32);
  GeometryCounters counters;
  auto tris = geometry(s, view, &counters);
  REQUIRE(tris.size() == 2);
  CHECK(counters.culledBackFace == 1);
  CHECK(tris[0].primitive == 0);
  CHECK(tris[0].backFacing == 0);
  CHECK(tris[1].primitive == 2);
  CHECK(tris[1].backFacing == 1);
  // The back face, re-wound, covers exactly the pixels of the front face.
  auto front = test::coverageCounts(32, 32, {tris[0]});
  auto back = test::coverageCounts(32, 32, {tris[1]});
  CHECK(front == back);
  int covered = 0;
  for (int v : front) covered += v;
  CHECK(covered > 100);
}

TEST_CASE("Geometry: vertices on pixel centres snap exactly") {
  scene::Scene s = test::emptyScene();
  // World (i + 0.5 - 16, 16 - j - 0.5) is the sample of pixel (i, j) for pixelOrthoCamera(32).
  test::addTriangle(s, {-15.5f, 15.5f, 0.0f}, {-15.5f, -4.5f, 0.0f}, {8.5f, 15.5f, 0.0f});
  auto tris = geometry(s, makeFrameView(test::pixelOrthoCamera(32), 32, 32));
  REQUIRE(tris.size() == 1);
  CHECK(tris[0].x[0] == 0 * 256 + 128);
  CHECK(tris[0].y[0] == 0 * 256 + 128);
  CHECK(tris[0].x[1] == 0 * 256 + 128);
  CHECK(tris[0].y[1] == 20 * 256 + 128);
  CHECK(tris[0].x[2] == 24 * 256 + 128);
  CHECK(tris[0].y[2] == 0 * 256 + 128);
}

TEST_CASE("Geometry: a triangle crossing the near plane and the camera plane matches ray casting") {
  constexpr int kW = 64, kH = 48;
  constexpr float kFov = 0.8f;
  scene::Scene s = test::emptyScene();
  // A floor triangle at y = -1 with one vertex behind the camera (z = +4: w < 0), front face up.
  glm::dvec3 a(-3, -1, -6), b(0, -1, 4), c(3, -1, -6);
  test::addTriangle(s, glm::vec3(a), glm::vec3(b), glm::vec3(c));
  FrameView view = makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}, kFov, 0.05f), kW, kH);
  GeometryCounters counters;
  auto tris = geometry(s, view, &counters);
  CHECK(counters.clipped == 1);
  REQUIRE(!tris.empty());
  CHECK(allFinite(tris));
  auto counts = test::coverageCounts(kW, kH, tris);
  int checked = 0, wrong = 0;
  for (int j = 0; j < kH; ++j) {
    for (int i = 0; i < kW; ++i) {
      glm::dvec3 d = pixelRay(i, j, kW, kH, kFov);
      int expected = 0;
      if (d.y < 0.0) {
        glm::dvec3 p = d * (-1.0 / d.y);
        // Barycentrics of p in the (x, z) plane; a sample within 0.02 of an edge is skipped.
        auto cross2 = [](glm::dvec3 u, glm::dvec3 v) { return u.x * v.z - u.z * v.x; };
        double area = cross2(b - a, c - a);
        double l1 = cross2(p - a, c - a) / area, l2 = cross2(b - a, p - a) / area, l0 = 1.0 - l1 - l2;
        double m = std::min({l0, l1, l2});
        if (std::abs(m) < 0.02) continue;
        expected = m > 0.0 ? 1 : 0;
      }
      ++checked;
      wrong += counts[size_t(j) * kW + i] != expected;
    }
  }
  CHECK(checked > kW * kH / 2);
  CHECK(wrong == 0);
}

TEST_CASE("Geometry: a tessellated floor cut by the near plane stays watertight") {
  constexpr int kW = 80, kH = 60, kN = 24;
  constexpr float kFov = 1.2f, kNear = 0.9f;
  scene::Scene s = test::emptyScene();
  // Floor y = -1 over x in [-20, 20], z in [-40, 8], seen from 1 unit above looking steeply
  // down with a near plane of 0.9: the near plane cuts the floor inside the picture, so
  // clipped triangles and their clipped shared edges are visible.
  auto vertex = [&](int i, int k) {
    return glm::vec3(-20.0f + 40.0f * i / kN, -1.0f, -40.0f + 48.0f * k / kN);
  };
  for (int k = 0; k < kN; ++k) {
    for (int i = 0; i < kN; ++i) {
      glm::vec3 p00 = vertex(i, k), p10 = vertex(i + 1, k), p01 = vertex(i, k + 1), p11 = vertex(i + 1, k + 1);
      // Counter-clockwise seen from above (+y).
      test::addTriangle(s, p00, p01, p11);
      test::addTriangle(s, p00, p11, p10);
    }
  }
  scene::Camera cam = test::lookAtCamera({0, 0, 0}, {0, -1, -0.3f}, kFov, kNear);
  FrameView view = makeFrameView(cam, kW, kH);
  GeometryCounters counters;
  auto tris = geometry(s, view, &counters);
  CHECK(counters.clipped > 0);
  CHECK(allFinite(tris));
  auto counts = test::coverageCounts(kW, kH, tris);
  int doubled = 0, wrong = 0, checkedIn = 0, checkedOut = 0;
  for (int j = 0; j < kH; ++j) {
    for (int i = 0; i < kW; ++i) {
      int c = counts[size_t(j) * kW + i];
      doubled += c > 1;
      // Ray cast: camera-space direction (x, y, -1) has view depth 1 per unit of t.
      glm::dvec3 d = pixelRay(i, j, kW, kH, kFov);
      glm::dvec3 dw = glm::dmat3(glm::dmat4(cam.cameraToWorld)) * d;
      if (dw.y >= 0.0) continue;
      double t = -1.0 / dw.y;  // = view depth of the hit point
      glm::dvec3 p = t * dw;
      bool inGrid = std::abs(p.x) < 19.5 && p.z > -39.5 && p.z < 7.5;
      if (inGrid && t > kNear * 1.01) {
        ++checkedIn;
        wrong += c != 1;
      } else if (t < kNear * 0.99) {
        ++checkedOut;
        wrong += c != 0;
      }
    }
  }
  CHECK(doubled == 0);
  CHECK(wrong == 0);
  CHECK(checkedIn > kW * kH / 4);
  CHECK(checkedOut > kW);
}

TEST_CASE("Geometry: huge triangles far outside the screen cover it exactly once") {
  constexpr int kW = 40, kH = 30;
  for (float extent : {1e4f, 1e7f, 1e15f}) {
    scene::Scene s = test::emptyScene();
    scene::Material twoSided = s.materials[0];
    twoSided.doubleSided = true;
    s.materials.push_back(twoSided);
    // A quad at z = -10 facing the camera, reaching `extent` in every direction.
    glm::vec3 p0(-extent, -extent, -10.0f), p1(extent, -extent, -10.0f), p2(extent, extent, -10.0f),
        p3(-extent, extent, -10.0f);
    test::addTriangle(s, p0, p1, p2);
    test::addTriangle(s, p0, p2, p3);
    // And a floor triangle reaching far behind the camera and far to the sides (seen from above:
    // a back face, hence double-sided).
    test::addTriangle(s, {-extent, -1.0f, -5.0f}, {extent, -1.0f, -5.0f}, {0.0f, -1.0f, extent}, 1);
    FrameView view = makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}), kW, kH);
    GeometryCounters counters;
    auto tris = geometry(s, view, &counters);
    CAPTURE(extent);
    CHECK(allFinite(tris));
    std::vector<ScreenTriangle> quad, wedge;
    for (const auto& t : tris) (t.primitive < 2 ? quad : wedge).push_back(t);
    auto counts = test::coverageCounts(kW, kH, quad);
    int notOnce = 0;
    for (int c : counts) notOnce += c != 1;
    CHECK(notOnce == 0);
    // The wedge is clipped (near plane, guard band) and still draws each pixel at most once.
    auto wedgeCounts = test::coverageCounts(kW, kH, wedge);
    int doubled = 0, covered = 0;
    for (int c : wedgeCounts) {
      doubled += c > 1;
      covered += c;
    }
    CHECK(doubled == 0);
    CHECK(covered > 0);
    CHECK(counters.clipped >= 1);
  }
}

TEST_CASE("Geometry: extreme depth ranges keep the nearer surface in front") {
  constexpr int kW = 32, kH = 24;
  struct Case {
    float znear, farZ, nearZ;
  };
  // Surfaces 1 unit apart at a million units with znear = 1e-6; surfaces 1e-6 apart just past
  // a near plane of 1e-6; and an orthographic-like spread in between.
  for (Case c : {Case{1e-6f, 1.0e6f, 999999.0f}, Case{1e-6f, 3e-6f, 2e-6f}, Case{0.1f, 1e4f, 1.0f}}) {
    for (bool nearFirst : {false, true}) {
      scene::Scene s = test::emptyScene();
      auto quad = [&](float z) {
        float e = 10.0f * z;  // covers the 0.8 rad field of view
        test::addTriangle(s, {-e, -e, -z}, {e, -e, -z}, {e, e, -z});
        test::addTriangle(s, {-e, -e, -z}, {e, e, -z}, {-e, e, -z});
      };
      quad(nearFirst ? c.nearZ : c.farZ);
      quad(nearFirst ? c.farZ : c.nearZ);
      scene::Camera cam = test::lookAtCamera({0, 0, 0}, {0, 0, -1}, 0.8f, c.znear);
      auto tris = geometry(s, makeFrameView(cam, kW, kH));
      CHECK(allFinite(tris));
      RegionFramebuffer fb(Rect{0, 0, kW, kH});
      rasterizeTriangles(tris, fb);
      uint32_t nearLo = nearFirst ? 0 : 2;
      int wrong = 0;
      for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
          uint64_t key = fb.key(x, y);
          wrong += !keyCovered(key) || keyPrimitive(key) < nearLo || keyPrimitive(key) > nearLo + 1 ||
                   !std::isfinite(keyDepth(key));
        }
      }
      CAPTURE(c.farZ);
      CAPTURE(nearFirst);
      CHECK(wrong == 0);
    }
  }
}

TEST_CASE("Geometry: random triangles through every clip plane stay finite and single-covering") {
  // Corners anywhere from 1e-3 to 1e7 units around the eye, in front and behind: near-plane
  // and guard-band clipping in every combination. Each primitive's pieces must cover a pixel
  // at most once (the fan of a clipped polygon does not overlap itself).
  constexpr int kW = 48, kH = 32;
  scene::Scene s = test::emptyScene();
  s.materials[0].doubleSided = true;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), exponent(-3.0f, 7.0f);
  auto coordinate = [&] { return std::copysign(std::pow(10.0f, exponent(rng)), unit(rng)); };
  for (int i = 0; i < 3000; ++i) {
    glm::vec3 p[3];
    for (auto& v : p) v = glm::vec3(coordinate(), coordinate(), coordinate());
    test::addTriangle(s, p[0], p[1], p[2]);
  }
  GeometryCounters counters;
  auto tris = geometry(s, makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}, 1.0f, 0.01f), kW, kH), &counters);
  CHECK(counters.clipped > 500);
  CHECK(tris.size() > 300);
  CHECK(allFinite(tris));
  int overlapping = 0;
  for (size_t i = 0; i < tris.size();) {
    size_t j = i;
    while (j < tris.size() && tris[j].primitive == tris[i].primitive) ++j;
    auto counts = test::coverageCounts(kW, kH, std::vector<ScreenTriangle>(tris.begin() + i, tris.begin() + j));
    for (int c : counts) overlapping += c > 1;
    i = j;
  }
  CHECK(overlapping == 0);
}

TEST_CASE("Geometry: triangles entirely outside or behind are rejected early") {
  scene::Scene s = test::emptyScene();
  test::addTriangle(s, {-1, -1, 5}, {1, -1, 5}, {0, 1, 5});        // behind the camera
  test::addTriangle(s, {100, -1, -5}, {102, -1, -5}, {101, 1, -5});  // far right of the frustum
  GeometryCounters counters;
  auto tris = geometry(s, makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}), 16, 16), &counters);
  CHECK(tris.empty());
  CHECK(counters.culledOutside == 2);
}

TEST_CASE("Geometry: non-finite and overflowing positions are dropped, not rasterized") {
  scene::Scene s = test::emptyScene();
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  test::addTriangle(s, {nan, 0, -5}, {1, 0, -5}, {0, 1, -5});
  test::addTriangle(s, {-1, 0, -5}, {inf, 0, -5}, {0, 1, -5});
  test::addTriangle(s, {-1, 0, -5}, {1, 0, -5}, {0, 3e38f, -5});  // overflows in the transform
  test::addTriangle(s, {-1, -1, -5}, {1, -1, -5}, {0, 1, -5});    // a normal one still draws
  GeometryCounters counters;
  auto tris = geometry(s, makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}), 16, 16), &counters);
  REQUIRE(tris.size() == 1);
  CHECK(tris[0].primitive == 3);
  CHECK(counters.culledDegenerate == 3);
}

TEST_CASE("Geometry: an image size outside the limits is an input error") {
  scene::Camera cam = test::lookAtCamera({0, 0, 0}, {0, 0, -1});
  CHECK_THROWS_AS(makeFrameView(cam, 0, 10), InputError);
  CHECK_THROWS_AS(makeFrameView(cam, 10, kMaxImageSidePx + 1), InputError);
  CHECK_NOTHROW(makeFrameView(cam, kMaxImageSidePx, 1));
}

}  // namespace
}  // namespace pr::raster

TEST_CASE("Geometry: the rasterizers order at most 2^29 triangles, an input error beyond") {
  // Fake counts: nothing of the size is allocated.
  auto messageOf = [](size_t n) {
    try {
      pr::raster::checkRasterLimits("scene big.gltf", n);
    } catch (const pr::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(pr::raster::kMaxPrimitives == (1u << 29));
  const std::string message = messageOf((size_t(1) << 29) + 1);
  CHECK(message.find("536870913 triangles exceed the limit of 536870912") != std::string::npos);
  CHECK(messageOf(size_t(1) << 29).empty());
}
