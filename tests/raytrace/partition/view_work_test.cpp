// Tests of the view-work estimate (raytrace/partition/view_work.cpp): a quad filling the view
// gives the image's pixels, half a view half of them, geometry behind the camera none, and a
// floor crossing the camera plane the lower half of the image, in pieces in front of it.
#include <doctest/doctest.h>

#include <limits>

#include "raytrace/core/geometry_builders.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/view_work.h"

using namespace pr;

namespace {

double total(const std::vector<rt::WorkPoint>& work) {
  double sum = 0.0;
  for (const rt::WorkPoint& w : work) sum += w.weight;
  return sum;
}

scene::Scene quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  scene::Scene s = test::emptyScene();
  test::addTriangle(s, a, b, c);
  test::addTriangle(s, a, c, d);
  return s;
}

}  // namespace

TEST_CASE("ViewWork: a quad over the whole view covers every pixel, in pieces of at most the piece size") {
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const scene::Scene s = quad({-100, -100, -5}, {100, -100, -5}, {100, 100, -5}, {-100, 100, -5});
  const std::vector<rt::WorkPoint> work = rt::viewWork(s, cam, 64, 32);
  CHECK(total(work) == doctest::Approx(64.0 * 32.0).epsilon(1e-3));
  CHECK(work.size() > 2);  // cut: 2048 pixels in pieces of at most 64
  for (const rt::WorkPoint& w : work) {
    CHECK(w.weight <= rt::kViewWorkPiecePixels);
    CHECK(w.position.z == doctest::Approx(-5.0f));
  }
}

TEST_CASE("ViewWork: half the view gives half the pixels, behind the camera, none") {
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const scene::Scene right = quad({0, -100, -5}, {100, -100, -5}, {100, 100, -5}, {0, 100, -5});
  CHECK(total(rt::viewWork(right, cam, 64, 32)) == doctest::Approx(32.0 * 32.0).epsilon(1e-3));
  const scene::Scene behind = quad({-100, -100, 5}, {100, -100, 5}, {100, 100, 5}, {-100, 100, 5});
  CHECK(rt::viewWork(behind, cam, 64, 32).empty());
}

TEST_CASE("ViewWork: a floor through the camera plane covers the lower half, in pieces in front of the camera") {
  // y = -1 from z = +50 (behind the eye) to z = -1e5: below the horizon, the lower half of the
  // image; the part nearer than the bottom edge of the view and the part behind give nothing.
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const scene::Scene floor = quad({-1e5f, -1, 50}, {1e5f, -1, 50}, {1e5f, -1, -1e5f}, {-1e5f, -1, -1e5f});
  const std::vector<rt::WorkPoint> work = rt::viewWork(floor, cam, 64, 32);
  CHECK(total(work) == doctest::Approx(64.0 * 16.0).epsilon(0.05));
  for (const rt::WorkPoint& w : work) CHECK(w.position.z < 0.0f);
}

TEST_CASE("ViewWork: a triangle with a non-finite vertex, or beyond float range in view, gives no work") {
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  scene::Scene s = test::emptyScene();
  test::addTriangle(s, {-1, -1, -5}, {1, -1, -5}, {nan, 1, -5});
  test::addTriangle(s, {-1, -1, -5}, {inf, -1, -5}, {0, 1, -5});
  test::addTriangle(s, {-1e38f, -1e38f, -1e-30f}, {1e38f, -1e38f, -1e-30f}, {0, 1e38f, -1e-30f});
  CHECK(total(rt::viewWork(s, cam, 64, 32)) == 0.0);
}
