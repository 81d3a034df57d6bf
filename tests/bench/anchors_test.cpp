// Tests of the benchmark anchors (tools/bench/anchors): Embree's closest hits and occlusion
// against a brute-force ray-triangle loop, and llvmpipe's coverage and shading of a triangle
// whose pixel footprint is known. Each part compiles only when its packages were found.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/glm.hpp>

#include "common/scene/camera.h"
#include "common/scene/scene.h"

#ifdef PARRENDER_HAVE_EMBREE_ANCHOR
#include "tools/bench/anchors/embree_anchor.h"
#endif
#ifdef PARRENDER_HAVE_LLVMPIPE_ANCHOR
#include "tools/bench/anchors/egl_context.h"
#include "tools/bench/anchors/llvmpipe_anchor.h"
#endif

namespace {

using pr::scene::Scene;

// A scene with one material and no geometry yet.
Scene sceneWithMaterial(glm::vec4 baseColor = glm::vec4(1.0f), bool doubleSided = false) {
  Scene s;
  pr::scene::Material m;
  m.baseColorFactor = baseColor;
  m.metallicFactor = 0.0f;
  m.doubleSided = doubleSided;
  s.materials.push_back(m);
  return s;
}

// Appends a triangle with its own three vertices and their geometric normal.
void addTriangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  const auto base = uint32_t(s.positions.size());
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  s.positions.insert(s.positions.end(), {a, b, c});
  s.normals.insert(s.normals.end(), {n, n, n});
  s.triangles.push_back(pr::scene::Triangle{{base, base + 1, base + 2}, 0});
}

// Deterministic uniform floats in [0, 1) (SplitMix64), so every run tests the same rays.
struct TestRng {
  uint64_t state;
  float next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return float((z ^ (z >> 31)) >> 40) / float(1ull << 24);
  }
  glm::vec3 inBox(float lo, float hi) { return glm::vec3(lo) + (hi - lo) * glm::vec3(next(), next(), next()); }
};

}  // namespace

#ifdef PARRENDER_HAVE_EMBREE_ANCHOR

namespace {

using pr::bench::EmbreeAnchor;
using pr::bench::HitOut;
using pr::bench::RayIn;

// Reference closest hit of one ray, Moeller-Trumbore per triangle in double precision.
// nearEdge marks a ray passing within rounding of some triangle's edge inside (tmin, tmax),
// and secondT the next-closest hit: such rays may legitimately go either way in float.
struct BruteHit {
  double t = std::numeric_limits<double>::infinity();
  uint32_t primID = HitOut::kMiss;
  double secondT = std::numeric_limits<double>::infinity();
  bool nearEdge = false;
};

BruteHit bruteForce(const Scene& s, const RayIn& ray) {
  constexpr double kEdge = 1e-4;  // barycentric margin, far above float rounding (~1e-7)
  BruteHit best;
  const glm::dvec3 o(ray.org), d(ray.dir);
  for (uint32_t i = 0; i < s.triangles.size(); ++i) {
    const glm::dvec3 p0(s.positions[s.triangles[i].v[0]]), p1(s.positions[s.triangles[i].v[1]]),
        p2(s.positions[s.triangles[i].v[2]]);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
    const double det = glm::dot(e1, pv);
    if (std::abs(det) < 1e-14) continue;
    const glm::dvec3 tv = o - p0;
    const double u = glm::dot(tv, pv) / det;
    const glm::dvec3 qv = glm::cross(tv, e1);
    const double v = glm::dot(d, qv) / det, t = glm::dot(e2, qv) / det;
    if (t <= ray.tmin || t >= ray.tmax) continue;
    const double margin = std::min({u, v, 1.0 - u - v});
    if (std::abs(margin) < kEdge) best.nearEdge = true;
    if (margin < 0.0) continue;
    if (t < best.t) {
      best.secondT = best.t;
      best.t = t;
      best.primID = i;
    } else {
      best.secondT = std::min(best.secondT, t);
    }
  }
  return best;
}

// 60 random triangles in [-1, 1]^3 and 3000 rays from a larger box towards points inside it.
Scene randomSoup() {
  Scene s = sceneWithMaterial();
  TestRng rng{42};
  for (int i = 0; i < 60; ++i) {
    const glm::vec3 centre = rng.inBox(-1.0f, 1.0f);
    addTriangle(s, centre + rng.inBox(-0.4f, 0.4f), centre + rng.inBox(-0.4f, 0.4f), centre + rng.inBox(-0.4f, 0.4f));
  }
  return s;
}

std::vector<RayIn> randomRays(size_t count, uint64_t seed) {
  TestRng rng{seed};
  std::vector<RayIn> rays;
  for (size_t i = 0; i < count; ++i) {
    const glm::vec3 org = rng.inBox(-3.0f, 3.0f), target = rng.inBox(-1.2f, 1.2f);
    rays.push_back(RayIn{org, glm::normalize(target - org), 0.0f, std::numeric_limits<float>::infinity()});
  }
  return rays;
}

// Every ray not grazing an edge and not nearly tied between two surfaces must agree exactly.
bool unambiguous(const BruteHit& b) {
  if (b.nearEdge) return false;
  return b.primID == HitOut::kMiss || (b.secondT - b.t) > 1e-4 * std::max(1.0, b.t);
}

}  // namespace

TEST_CASE("EmbreeAnchor: closest hits equal a brute-force ray-triangle loop") {
  const Scene s = randomSoup();
  const EmbreeAnchor anchor(s);
  CHECK(anchor.triangleCount() == 60);
  CHECK(anchor.buildSeconds() >= 0.0);
  const std::vector<RayIn> rays = randomRays(3000, 7);
  const pr::bench::TraceResult result = anchor.traceClosest(rays, 1);
  REQUIRE(result.hits.size() == rays.size());
  CHECK(result.rays == rays.size());
  size_t compared = 0, hits = 0, misses = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const BruteHit ref = bruteForce(s, rays[i]);
    const HitOut& got = result.hits[i];
    if (!unambiguous(ref)) continue;
    ++compared;
    if (ref.primID == HitOut::kMiss) {
      CHECK(!got.hit());
      ++misses;
      continue;
    }
    ++hits;
    REQUIRE(got.hit());
    CHECK(got.primID == ref.primID);
    CHECK(got.t == doctest::Approx(ref.t).epsilon(1e-5));
  }
  // The soup is dense enough that both cases occur often; otherwise the test proves little.
  CHECK(hits > 500);
  CHECK(misses > 300);
  CHECK(compared > 0.9 * double(rays.size()));
}

TEST_CASE("EmbreeAnchor: occlusion equals a brute-force any-hit test within tmax") {
  const Scene s = randomSoup();
  const EmbreeAnchor anchor(s);
  std::vector<RayIn> rays = randomRays(2000, 11);
  // Shadow rays end at a random distance, so some stop before the first surface and some after.
  TestRng rng{5};
  for (RayIn& r : rays) r.tmax = 1.0f + 5.0f * rng.next();
  const pr::bench::TraceResult result = anchor.traceOcclusion(rays, 1);
  REQUIRE(result.occluded.size() == rays.size());
  size_t occluded = 0, unoccluded = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    // Occluded exactly when the first surface along the unbounded ray lies before tmax; rays
    // grazing an edge or meeting their first surface within rounding of tmax are set aside.
    const BruteHit first = bruteForce(s, RayIn{rays[i].org, rays[i].dir, 0.0f, std::numeric_limits<float>::infinity()});
    if (first.nearEdge || std::abs(first.t - rays[i].tmax) < 1e-4) continue;
    const bool expected = first.t < rays[i].tmax;
    CHECK(bool(result.occluded[i]) == expected);
    (expected ? occluded : unoccluded) += 1;
  }
  CHECK(occluded > 200);
  CHECK(unoccluded > 200);
}

TEST_CASE("EmbreeAnchor: two threads trace the same hits as one") {
  const Scene s = randomSoup();
  const EmbreeAnchor anchor(s);
  const std::vector<RayIn> rays = randomRays(1001, 3);  // odd count: chunks of unequal size
  const pr::bench::TraceResult one = anchor.traceClosest(rays, 1);
  const pr::bench::TraceResult two = anchor.traceClosest(rays, 2);
  CHECK(two.threads == 2);
  CHECK(one.rays == 1001);
  CHECK(one.cpuSeconds > 0.0);
  CHECK(one.mraysPerCpuSecond > 0.0);
  REQUIRE(two.hits.size() == one.hits.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    CHECK(two.hits[i].primID == one.hits[i].primID);
    CHECK(two.hits[i].t == one.hits[i].t);
  }
  CHECK(two.hitCount == one.hitCount);
  CHECK(anchor.traceOcclusion(rays, 2).occluded == anchor.traceOcclusion(rays, 1).occluded);
  CHECK_THROWS_AS(anchor.traceClosest(rays, 0), std::invalid_argument);
}

TEST_CASE("EmbreeAnchor: primary rays of a camera hit the wall in front at its distance") {
  // A wall at z = -5 filling the view of a camera at the origin looking down -Z.
  Scene s = sceneWithMaterial();
  addTriangle(s, {-100.0f, -100.0f, -5.0f}, {100.0f, -100.0f, -5.0f}, {0.0f, 100.0f, -5.0f});
  pr::scene::Camera camera;
  camera.yfov = 0.8f;
  camera.znear = 0.1f;
  const std::vector<RayIn> rays = pr::bench::primaryRays(camera, 9, 7);
  REQUIRE(rays.size() == 63);
  // The centre pixel (4, 3) looks straight down -Z from the near plane.
  const RayIn& centre = rays[3 * 9 + 4];
  CHECK(centre.dir.z == doctest::Approx(-1.0f));
  CHECK(centre.org.z == doctest::Approx(-0.1f));
  // Row 0 is the top of the picture: its rays point up (+y), the last row's down.
  CHECK(rays[4].dir.y > 0.0f);
  CHECK(rays[6 * 9 + 4].dir.y < 0.0f);
  const EmbreeAnchor anchor(s);
  const pr::bench::TraceResult result = anchor.traceClosest(rays, 1);
  CHECK(result.hitCount == rays.size());
  // Distance along a unit direction from the near plane point to the plane z = -5.
  for (size_t i = 0; i < rays.size(); ++i)
    CHECK(result.hits[i].t == doctest::Approx((-5.0f - rays[i].org.z) / rays[i].dir.z).epsilon(1e-5));
}

TEST_CASE("EmbreeAnchor: a scene without triangles misses every ray") {
  const Scene s = sceneWithMaterial();
  const EmbreeAnchor anchor(s);
  const pr::bench::TraceResult result = anchor.traceClosest(randomRays(50, 1), 1);
  CHECK(result.hitCount == 0);
  for (const HitOut& h : result.hits) CHECK(!h.hit());
}

#endif  // PARRENDER_HAVE_EMBREE_ANCHOR

#ifdef PARRENDER_HAVE_LLVMPIPE_ANCHOR

namespace {

// Every llvmpipe case uses the same LP_NUM_THREADS, because the whole test program (when run
// without ctest) shares one llvmpipe context.
constexpr int kTestThreads = 0;

// Pixel centres covered by the right triangle (-0.5,-0.5), (0.5,-0.5), (-0.5,0.5) on a 64 x 64
// image of unitOrthoCamera(): its legs span pixels 16..47, so centres (i + 0.5, j + 0.5) with
// i, j in [0, 32) are inside when i + j < 31 (32 * 31 / 2) and on the hypotenuse when i + j = 31.
constexpr int kInside = 496;
constexpr int kOnHypotenuse = 32;

// An orthographic camera at the origin looking down -Z that sees x, y in [-1, 1]: on a
// 64 x 64 image one scene unit is 32 pixels.
pr::scene::Camera unitOrthoCamera() {
  pr::scene::Camera camera;
  camera.projection = pr::scene::Projection::Orthographic;
  camera.xmag = camera.ymag = 1.0f;
  camera.znear = 0.01f;
  camera.zfar = 10.0f;
  return camera;
}

// Runs the anchor; when this machine has no usable llvmpipe, prints the line CTest reads as
// "skipped" and returns false.
bool render(const Scene& s, int size, pr::bench::RasterAnchorResult& out, int frames = 2) {
  try {
    out = pr::bench::renderWithLlvmpipe(s, unitOrthoCamera(), size, size, kTestThreads, frames);
    return true;
  } catch (const pr::bench::AnchorUnavailable& e) {
    std::printf("SKIPPED: %s\n", e.what());
    return false;
  }
}

}  // namespace

TEST_CASE("LlvmpipeAnchor: a known triangle covers its area in pixels, shaded by the headlight") {
  // Right triangle with 1-unit legs = 32-pixel legs on pixel boundaries (512 pixels of area).
  // 496 pixel centres lie strictly inside; the 32 on the hypotenuse (it runs through pixel
  // centres) go to this triangle or not by the fill rule's tie-breaking, so 496..528.
  Scene s = sceneWithMaterial(glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  addTriangle(s, {-0.5f, -0.5f, -1.0f}, {0.5f, -0.5f, -1.0f}, {-0.5f, 0.5f, -1.0f});
  pr::bench::RasterAnchorResult r;
  if (!render(s, 64, r)) return;
  CHECK(r.renderer.find("llvmpipe") != std::string::npos);
  CHECK(r.width == 64);
  CHECK(r.coveredPixels >= kInside);
  CHECK(r.coveredPixels <= kInside + kOnHypotenuse);
  REQUIRE(r.coverage.size() == 64 * 64);
  // Row 0 is the top: the triangle's right angle is bottom-left, at pixels (16..47, 16..47).
  CHECK(r.coverage[size_t(40) * 64 + 20] == 1);   // near the bottom-left corner
  CHECK(r.coverage[size_t(20) * 64 + 44] == 0);   // top-right half, outside the hypotenuse
  CHECK(r.coverage[size_t(5) * 64 + 5] == 0);     // background
  // Headlight (no lights): radiance = base * N.V = base, the normal facing the camera.
  const uint8_t* pixel = &r.rgba[(size_t(40) * 64 + 20) * 4];
  CHECK(int(pixel[0]) == doctest::Approx(128).epsilon(0.01));
  CHECK(int(pixel[1]) == doctest::Approx(64).epsilon(0.02));
  CHECK(int(pixel[2]) == 255);
  CHECK(int(pixel[3]) == 255);
  int counted = 0;
  for (uint8_t c : r.coverage) counted += c;
  CHECK(counted == r.coveredPixels);
}

TEST_CASE("LlvmpipeAnchor: back faces are culled unless the material is double-sided") {
  // The same triangle wound clockwise as seen from the camera: a back face.
  Scene single = sceneWithMaterial();
  addTriangle(single, {-0.5f, -0.5f, -1.0f}, {-0.5f, 0.5f, -1.0f}, {0.5f, -0.5f, -1.0f});
  pr::bench::RasterAnchorResult r;
  if (!render(single, 64, r)) return;
  CHECK(r.coveredPixels == 0);
  Scene both = single;
  both.materials[0].doubleSided = true;
  if (!render(both, 64, r)) return;
  CHECK(r.coveredPixels >= kInside);
  CHECK(r.coveredPixels <= kInside + kOnHypotenuse);
}

TEST_CASE("LlvmpipeAnchor: the nearer of two overlapping triangles wins, and a point light shades it") {
  // A full-view red quad at z = -2 behind a small green triangle at z = -1; a point light of
  // intensity I at the camera: E = I / d^2 on the green triangle (d = 1 at its centre line).
  Scene s = sceneWithMaterial(glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  addTriangle(s, {-1.0f, -1.0f, -2.0f}, {1.0f, -1.0f, -2.0f}, {1.0f, 1.0f, -2.0f});
  addTriangle(s, {-1.0f, -1.0f, -2.0f}, {1.0f, 1.0f, -2.0f}, {-1.0f, 1.0f, -2.0f});
  pr::scene::Material green = s.materials[0];
  green.baseColorFactor = glm::vec4(0.0f, 1.0f, 0.0f, 1.0f);
  s.materials.push_back(green);
  addTriangle(s, {-0.25f, -0.25f, -1.0f}, {0.25f, -0.25f, -1.0f}, {0.0f, 0.25f, -1.0f});
  s.triangles.back().material = 1;
  pr::scene::PunctualLight light;
  light.position = glm::vec3(0.0f);
  light.intensity = 0.5f * 3.14159265f;  // radiance = base / pi * E * cos = 0.5 at d = 1, cos = 1
  s.lights.push_back(light);
  pr::bench::RasterAnchorResult r;
  if (!render(s, 64, r, 3)) return;
  CHECK(r.frameMs.size() == 3);
  CHECK(r.frameCpuMs.size() == 3);
  CHECK(r.msPerFrameMedian > 0.0);
  CHECK(r.coveredPixels == 64 * 64);
  // Expected 8-bit value at pixel (x, y) on the plane z: the pixel centre's world point p
  // (orthographic: x, y straight from NDC), d^2 = |p|^2, cos = |z| / |p| for the normal +Z,
  // radiance = base / pi * (I / d^2) * cos = 0.5 |z| / |p|^3.
  const auto expected = [](int x, int y, float z) {
    const glm::vec3 p(2.0f * (float(x) + 0.5f) / 64.0f - 1.0f, 1.0f - 2.0f * (float(y) + 0.5f) / 64.0f, z);
    const float d = glm::length(p);
    return 255.0 * 0.5 * std::abs(z) / (d * d * d);
  };
  // Pixel (32, 36), just below the image centre, lies inside the green triangle (~124).
  const uint8_t* inner = &r.rgba[(size_t(36) * 64 + 32) * 4];
  CHECK(int(inner[0]) == 0);
  CHECK(double(inner[1]) == doctest::Approx(expected(32, 36, -1.0f)).epsilon(0.02));
  // Corner pixel (0, 0) sees the red quad (~18).
  const uint8_t* corner = &r.rgba[0];
  CHECK(double(corner[0]) == doctest::Approx(expected(0, 0, -2.0f)).epsilon(0.08));
  CHECK(int(corner[1]) == 0);
}

TEST_CASE("LlvmpipeAnchor: one thread count per process, bad sizes rejected") {
  Scene s = sceneWithMaterial();
  addTriangle(s, {-0.5f, -0.5f, -1.0f}, {0.5f, -0.5f, -1.0f}, {-0.5f, 0.5f, -1.0f});
  pr::bench::RasterAnchorResult r;
  if (!render(s, 16, r, 1)) return;
  CHECK(r.threads == kTestThreads);
  CHECK_THROWS_AS(pr::bench::renderWithLlvmpipe(s, unitOrthoCamera(), 16, 16, kTestThreads + 1, 1), std::logic_error);
  CHECK_THROWS_AS(pr::bench::renderWithLlvmpipe(s, unitOrthoCamera(), 0, 16, kTestThreads, 1), std::invalid_argument);
  CHECK_THROWS_AS(pr::bench::renderWithLlvmpipe(s, unitOrthoCamera(), 16, 16, kTestThreads, 0), std::invalid_argument);
}

#endif  // PARRENDER_HAVE_LLVMPIPE_ANCHOR

#if defined(PARRENDER_HAVE_EMBREE_ANCHOR) && defined(PARRENDER_HAVE_LLVMPIPE_ANCHOR)

TEST_CASE("Anchors: llvmpipe coverage and Embree primary-ray hits agree off the edges") {
  // A perspective camera at (0, 0, 3) looking down -Z at a tilted triangle: a pixel is covered
  // by llvmpipe exactly when the ray through its centre hits the triangle, so the two masks may
  // differ only on pixels an edge passes through (a benchmark compares them the same way).
  Scene s = sceneWithMaterial(glm::vec4(1.0f), true);
  addTriangle(s, {-1.2f, -0.9f, 0.3f}, {1.1f, -0.7f, -0.4f}, {0.1f, 1.0f, 0.0f});
  pr::scene::Camera camera;
  camera.cameraToWorld[3] = glm::vec4(0.0f, 0.0f, 3.0f, 1.0f);
  camera.yfov = 0.9f;
  camera.znear = 0.1f;
  constexpr int kWidth = 80, kHeight = 60;
  pr::bench::RasterAnchorResult raster;
  try {
    raster = pr::bench::renderWithLlvmpipe(s, camera, kWidth, kHeight, kTestThreads, 1);
  } catch (const pr::bench::AnchorUnavailable& e) {
    std::printf("SKIPPED: %s\n", e.what());
    return;
  }
  const EmbreeAnchor anchor(s);
  const pr::bench::TraceResult rays = anchor.traceClosest(pr::bench::primaryRays(camera, kWidth, kHeight), 1);
  int differing = 0;
  for (size_t i = 0; i < rays.hits.size(); ++i) differing += int(raster.coverage[i] != (rays.hits[i].hit() ? 1 : 0));
  // A tie on a pixel centre is decided by different rules; anything else would be a wrong
  // projection, a flipped row order or a different aspect (each would change hundreds).
  CHECK(raster.coveredPixels > 600);  // 872 of 4800 pixels
  CHECK(size_t(raster.coveredPixels) == doctest::Approx(double(rays.hitCount)).epsilon(0.01));
  CHECK(differing <= 10);
}

#endif  // both anchors
