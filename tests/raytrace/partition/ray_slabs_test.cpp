// RaySlabs: the four-lane test of a group of boxes agrees with the test of each box alone, on
// rays of every kind the tracers make, including rays parallel to an axis and origins on faces.
#include "raytrace/partition/ray_slabs.h"

#include <doctest/doctest.h>

#include <array>
#include <random>

namespace {

using pr::rt::Ray;
using pr::rt::RaySlabs;
using pr::rt::SlabBox;
using pr::rt::SlabBoxes4;
using pr::scene::Bounds;

// Coordinates on a coarse grid, so that origins often lie exactly on a box's face.
float gridValue(std::mt19937& rng) { return float(std::uniform_int_distribution<int>(-8, 8)(rng)) * 0.5f; }

Bounds randomBox(std::mt19937& rng) {
  Bounds b;
  b.extend(glm::vec3(gridValue(rng), gridValue(rng), gridValue(rng)));
  b.extend(glm::vec3(gridValue(rng), gridValue(rng), gridValue(rng)));
  return b;
}

Ray randomRay(std::mt19937& rng) {
  Ray r;
  r.origin = glm::vec3(gridValue(rng), gridValue(rng), gridValue(rng));
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  glm::vec3 d(u(rng), u(rng), u(rng));
  // One ray in four parallel to an axis plane, one in eight to two of them.
  const int kind = std::uniform_int_distribution<int>(0, 7)(rng);
  if (kind < 2) d[kind] = 0.0f;
  if (kind == 2) d.x = d.y = 0.0f;
  if (glm::length(d) == 0.0f) d = glm::vec3(0.0f, 0.0f, 1.0f);
  r.direction = glm::normalize(d);
  r.tMin = 0.0f;
  r.tMax = std::uniform_int_distribution<int>(0, 1)(rng) ? std::numeric_limits<float>::infinity() : 6.0f;
  return r;
}

}  // namespace

TEST_CASE("RaySlabs: four boxes at once give the answer of testing each box") {
  std::mt19937 rng(17);
  int reached = 0, missed = 0;
  for (int i = 0; i < 20000; ++i) {
    const int n = std::uniform_int_distribution<int>(1, 4)(rng);
    std::array<Bounds, 4> boxes;
    for (int k = 0; k < n; ++k) boxes[size_t(k)] = randomBox(rng);
    const Ray ray = randomRay(rng);
    const RaySlabs slabs(ray);
    const float t0 = std::uniform_int_distribution<int>(0, 1)(rng) ? ray.tMin : 1.0f;
    const float t1 = std::uniform_int_distribution<int>(0, 1)(rng) ? ray.tMax : 3.0f;
    const float grow = i % 2 == 0 ? 0.0f : 0.01f;  // ungrown, origins lie on faces
    // The one-box test: entry() of the same ray clipped to [t0, t1].
    Ray clipped = ray;
    clipped.tMin = t0;
    clipped.tMax = t1;
    const RaySlabs one(clipped);
    bool any = false;
    float t = 0.0f;
    for (int k = 0; k < n; ++k) any = any || one.entry(SlabBox::of(boxes[size_t(k)], grow), t);
    const bool all4 = slabs.overlapsAny(SlabBoxes4::of(boxes.data(), size_t(n), grow), t0, t1);
    CAPTURE(i);
    CHECK(all4 == any);
    ++(any ? reached : missed);
  }
  // Both answers are common, so the agreement says something.
  CHECK(reached > 2000);
  CHECK(missed > 2000);
}

TEST_CASE("RaySlabs: a ray parallel to a slab misses a box outside it and reaches one it starts in") {
  Ray ray;
  ray.origin = glm::vec3(0.0f, 2.0f, -5.0f);
  ray.direction = glm::vec3(0.0f, 0.0f, 1.0f);
  const RaySlabs slabs(ray);
  const Bounds beside{glm::vec3(-1.0f, -1.0f, -1.0f), glm::vec3(1.0f, 1.0f, 1.0f)};  // y below the ray
  const Bounds ahead{glm::vec3(-1.0f, 2.0f, -1.0f), glm::vec3(1.0f, 3.0f, 1.0f)};    // the ray on its face y = 2
  const Bounds under{glm::vec3(-1.0f, 1.0f, -1.0f), glm::vec3(1.0f, 2.0f, 1.0f)};    // the ray on its face y = 2
  CHECK_FALSE(slabs.overlapsAny(SlabBoxes4::of(&beside, 1), 0.0f, 100.0f));
  CHECK(slabs.overlapsAny(SlabBoxes4::of(&ahead, 1), 0.0f, 100.0f));
  CHECK(slabs.overlapsAny(SlabBoxes4::of(&under, 1), 0.0f, 100.0f));
  const std::array<Bounds, 2> both{beside, ahead};
  CHECK(slabs.overlapsAny(SlabBoxes4::of(both.data(), 2), 0.0f, 100.0f));
  // Before the box: the span ends at t = 3, the box starts at t = 4.
  CHECK_FALSE(slabs.overlapsAny(SlabBoxes4::of(both.data(), 2), 0.0f, 3.0f));
}
