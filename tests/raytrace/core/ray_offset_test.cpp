// Tests of robust secondary-ray origins (raytrace/core/ray_offset.h, spawn* in interaction.cpp):
// rays leaving a surface never hit it again (no acne) and never slip through a closed box
// (no leaks), at scene scales from 1e-4 to 1e5 and far from the coordinate origin, and 1000
// bounces of total internal reflection stay inside a glass box at scales 1e-6 to 1e6.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/core/interaction.h"
#include "raytrace/core/ray_offset.h"
#include "raytrace/integrators/bsdf.h"

using pr::rt::Bvh;
using pr::rt::Hit;
using pr::rt::Ray;
using pr::rt::SurfaceInteraction;

namespace {

constexpr int kCells = 4;  // quads per box edge: each face holds 2 * kCells^2 triangles

int faceOf(uint32_t triangle) { return int(triangle) / (2 * kCells * kCells); }

// A unit direction making angle acos(cosTheta) with n, around it at angle phi.
glm::vec3 aroundNormal(const glm::vec3& n, float cosTheta, float phi) {
  const glm::vec3 t = glm::normalize(std::fabs(n.x) > 0.5f ? glm::cross(n, glm::vec3(0, 1, 0)) : glm::cross(n, glm::vec3(1, 0, 0)));
  const glm::vec3 b = glm::cross(n, t);
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return glm::normalize(cosTheta * n + sinTheta * (std::cos(phi) * t + std::sin(phi) * b));
}

struct OffsetCase {
  glm::vec3 lo, hi;
};

// Within 8 ulps of a second face of the box: there the rounded point may lie just outside the
// neighbouring face, and a ray along the face may legitimately cross it at the seam.
bool nearEdge(const glm::vec3& p, const OffsetCase& c) {
  int planes = 0;
  for (int a = 0; a < 3; ++a) {
    const float ulp = std::nextafter(std::max(std::fabs(c.lo[a]), std::fabs(c.hi[a])), pr::rt::kInfinity) -
                      std::max(std::fabs(c.lo[a]), std::fabs(c.hi[a]));
    planes += std::fabs(p[a] - c.lo[a]) <= 8.0f * ulp || std::fabs(p[a] - c.hi[a]) <= 8.0f * ulp;
  }
  return planes >= 2;
}

}  // namespace

TEST_CASE("RayOffset: rays leaving the inside of a closed box neither re-hit their face nor leak") {
  const OffsetCase cases[] = {
      {glm::vec3(-1e-4f), glm::vec3(1.3e-4f)},              // tiny
      {glm::vec3(-1.0f, -0.5f, -2.0f), glm::vec3(1.5f, 2.0f, 0.25f)},
      {glm::vec3(-1e5f), glm::vec3(0.7e5f)},                // huge
      {glm::vec3(1e4f, -2e4f, 3e4f), glm::vec3(1e4f + 1.0f, -2e4f + 2.0f, 3e4f + 1.5f)},  // small, far out
      {glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(10.0f, 1e5f, 1.0f)},  // long and thin
  };
  for (const OffsetCase& c : cases) {
    CAPTURE(c.lo.x);
    CAPTURE(c.hi.y);
    const auto box = pr::test::closedBox(c.lo, c.hi, kCells);
    const Bvh bvh(box);
    const glm::vec3 centre = 0.5f * (c.lo + c.hi), half = 0.5f * (c.hi - c.lo);
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-0.9f, 0.9f);
    int reHits = 0, leaks = 0, exitHits = 0, blockedShadows = 0, samples = 0;
    SurfaceInteraction previous;
    for (int i = 0; i < 1500; ++i) {
      // A surface point found by a primary ray from inside, as a tracer would find it.
      const glm::vec3 origin = centre + half * glm::vec3(sym(rng), sym(rng), sym(rng));
      const Ray primary{origin, 0.0f, pr::test::randomDirection(rng), pr::rt::kInfinity};
      Hit hit;
      REQUIRE(bvh.intersect(primary, hit));
      const SurfaceInteraction si = pr::rt::makeInteraction(box, primary, hit);
      CHECK_FALSE(si.frontFace);  // hit from inside: the back of an outward-wound face
      const glm::vec3 inward = -si.geometricNormal;
      // Into the box, from steep to grazing (cos down to 1e-4): must hit another face.
      const float cosTheta = i % 3 == 0 ? std::pow(10.0f, -4.0f * unit(rng)) : unit(rng);
      const Ray bounce = pr::rt::spawnRay(si, aroundNormal(inward, std::max(cosTheta, 1e-4f), 6.2831853f * unit(rng)));
      Hit next;
      if (!bvh.intersect(bounce, next)) ++leaks;
      else if (faceOf(next.triangle) == faceOf(hit.triangle)) ++reHits;
      // Out through the wall (a refracted ray): nothing lies outside a convex box.
      const Ray out = pr::rt::spawnRay(si, aroundNormal(si.geometricNormal, std::max(unit(rng), 1e-4f), 6.2831853f * unit(rng)));
      exitHits += bvh.occluded(out);
      // Between two points on the inside of a convex box nothing can block a shadow ray. A
      // point rounded onto the other face's plane (dot = 0, a grazing pair that carries no
      // light) may be offset to the outside, so those pairs are left out, as are points at a
      // seam (nearEdge).
      const bool facing = i > 0 && glm::dot(previous.position - si.position, si.geometricNormal) < 0.0f &&
                          glm::dot(si.position - previous.position, previous.geometricNormal) < 0.0f &&
                          !nearEdge(si.position, c) && !nearEdge(previous.position, c);
      if (facing) blockedShadows += bvh.occluded(pr::rt::spawnRayTo(si, previous));
      previous = si;
      ++samples;
    }
    CHECK(samples == 1500);
    CHECK(reHits == 0);
    CHECK(leaks == 0);
    CHECK(exitHits == 0);
    CHECK(blockedShadows == 0);
  }
}

TEST_CASE("RayOffset: the offset point lies on the requested side and close to the surface") {
  for (float magnitude : {1e-4f, 1.0f, 1e5f}) {
    CAPTURE(magnitude);
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
    for (const glm::vec3& p : {glm::vec3(0.0f), magnitude * glm::vec3(0.9f, -0.6f, 0.01f), magnitude * glm::vec3(-1.0f, 1.0f, 1.0f)}) {
      const glm::vec3 up = pr::rt::offsetRayOrigin(p, n, glm::vec3(magnitude));
      const glm::vec3 down = pr::rt::offsetRayOrigin(p, -n, glm::vec3(magnitude));
      CHECK(glm::dot(up - p, n) > 0.0f);
      CHECK(glm::dot(down - p, n) < 0.0f);
      // 256 ulps of a coordinate, or 2^-16 of the magnitude near zero: below 1e-4 relative.
      CHECK(glm::length(up - p) < 1e-4f * magnitude);
    }
  }
}

TEST_CASE("RayOffset: 1000 bounces of total internal reflection stay inside a glass box, finite, at scales 1e-6 to 1e6") {
  // Inside a box of ior 2.4 (critical angle 24.6 degrees), a direction whose components are all
  // well above sin(24.6) keeps them under mirror reflection: every hit reflects totally, with
  // Fresnel reflectance exactly 1. Each bounce must hit the box from inside again (no leak, no
  // re-hit of the same face), at a finite positive distance, with the throughput still 1.
  constexpr float kIor = 2.4f;
  for (float scale : {1e-6f, 1e-3f, 1.0f, 1e3f, 1e6f}) {
    CAPTURE(scale);
    const glm::vec3 lo = scale * glm::vec3(-1.0f, -0.7f, -1.3f), hi = scale * glm::vec3(1.1f, 0.9f, 0.8f);
    const auto box = pr::test::closedBox(lo, hi, kCells);
    const Bvh bvh(box);
    Ray ray{0.5f * (lo + hi), 0.0f, glm::normalize(glm::vec3(0.55f, 0.6f, -0.58f)), pr::rt::kInfinity};
    float throughput = 1.0f;
    int bounces = 0, previousFace = -1;
    for (; bounces < 1000; ++bounces) {
      Hit hit;
      if (!bvh.intersect(ray, hit)) break;
      if (!(hit.t > 0.0f) || !std::isfinite(hit.t)) break;
      const SurfaceInteraction si = pr::rt::makeInteraction(box, ray, hit);
      if (si.frontFace || faceOf(hit.triangle) == previousFace) break;  // leaked out, or re-hit
      previousFace = faceOf(hit.triangle);
      const glm::vec3 n = -si.geometricNormal;  // into the glass
      const float cosI = glm::dot(-ray.direction, n);
      // Leaving glass into air: eta = 1 / ior; above the critical angle the reflectance is 1.
      throughput *= pr::rt::fresnelDielectric(cosI, 1.0f / kIor);
      const glm::vec3 reflected = glm::normalize(ray.direction + 2.0f * cosI * n);
      if (!std::isfinite(throughput) || !std::isfinite(reflected.x + reflected.y + reflected.z)) break;
      ray = pr::rt::spawnRay(si, reflected);
    }
    CHECK(bounces == 1000);
    CHECK(throughput == 1.0f);
    const glm::vec3 p = ray.origin;
    CHECK(glm::all(glm::greaterThanEqual(p, lo - 1e-3f * scale)));
    CHECK(glm::all(glm::lessThanEqual(p, hi + 1e-3f * scale)));
  }
}
