// LightSampler: punctual lights follow the glTF KHR_lights_punctual laws (inverse square,
// spot cone, range window, directional irradiance); area-light samples report the pdf that
// areaPdf recomputes for the same point (what MIS against BSDF sampling relies on).
#include <cmath>

#include <doctest/doctest.h>

#include "raytrace/core/bvh.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/integrators/light_sampler.h"
#include "raytrace/integrators/sampling.h"

using namespace pr;

namespace {

// The interaction at the ground point (x, 0, z) of a scene whose triangles 0-1 are the ground.
rt::SurfaceInteraction groundPoint(const scene::Scene& s, float x, float z) {
  const rt::Bvh bvh(s);
  const rt::Ray down{glm::vec3(x, 1.0f, z), 0.0f, glm::vec3(0.0f, -1.0f, 0.0f), rt::kInfinity};
  rt::Hit hit;
  REQUIRE(bvh.intersect(down, hit));
  return rt::makeInteraction(s, down, hit);
}

scene::Scene groundScene() {
  scene::Scene s;
  test::addGround(s, 10.0f, test::addMaterial(s, test::diffuse(0.5f)));
  return s;
}

}  // namespace

TEST_CASE("LightSampler: point light irradiance is I / d^2 towards the light") {
  const scene::Scene s = groundScene();
  const rt::LightSampler lights(s);
  scene::PunctualLight p;
  p.position = glm::vec3(3.0f, 4.0f, 0.0f);
  p.intensity = 50.0f;
  rt::LightSample ls;
  REQUIRE(lights.samplePunctual(p, groundPoint(s, 0.0f, 0.0f), ls));
  CHECK(ls.radiance.x == doctest::Approx(50.0 / 25.0));
  CHECK(ls.wi.x == doctest::Approx(0.6));
  CHECK(ls.wi.y == doctest::Approx(0.8));
  CHECK(ls.pdf == 0.0f);
}

TEST_CASE("LightSampler: spot cone, range window and directional light") {
  const scene::Scene s = groundScene();
  const rt::LightSampler lights(s);
  const rt::SurfaceInteraction si = groundPoint(s, 0.0f, 0.0f);
  scene::PunctualLight spot;
  spot.type = scene::LightType::Spot;
  spot.position = glm::vec3(0.0f, 2.0f, 0.0f);
  spot.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  spot.innerConeAngle = 0.2f;
  spot.outerConeAngle = 0.4f;
  rt::LightSample ls;
  REQUIRE(lights.samplePunctual(spot, si, ls));  // on the axis: full intensity
  CHECK(ls.radiance.x == doctest::Approx(1.0 / 4.0));
  spot.direction = glm::normalize(glm::vec3(1.0f, -1.0f, 0.0f));  // 45 degrees off: outside the cone
  CHECK_FALSE(lights.samplePunctual(spot, si, ls));
  scene::PunctualLight point;
  point.position = glm::vec3(0.0f, 2.0f, 0.0f);
  point.range = 1.5f;  // the point is 2 away: beyond the range, no light
  CHECK_FALSE(lights.samplePunctual(point, si, ls));
  scene::PunctualLight sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  sun.intensity = 3.0f;
  REQUIRE(lights.samplePunctual(sun, si, ls));
  CHECK(ls.radiance.x == doctest::Approx(3.0));
  CHECK(ls.shadowRay.tMax == rt::kInfinity);
}

TEST_CASE("LightSampler: area samples carry the pdf areaPdf recomputes, and face the point") {
  scene::Scene s = groundScene();
  scene::Material lamp = test::diffuse(0.0f);
  lamp.emissiveFactor = glm::vec3(2.0f);
  const uint32_t m = test::addMaterial(s, lamp);
  // Two emitting triangles facing down (wound clockwise seen from above), one twice as large.
  test::addTri(s, {0, 2, 0}, {1, 2, 0}, {0, 2, 1}, m);
  test::addTri(s, {2, 2, 0}, {4, 2, 0}, {2, 2, 1}, m);
  test::addAreaLights(s, m);
  const rt::LightSampler lights(s);
  const rt::SurfaceInteraction si = groundPoint(s, 1.0f, 0.5f);
  int count[2] = {0, 0};
  for (uint32_t i = 0; i < 400; ++i) {
    rt::LightSample ls;
    REQUIRE(lights.sampleArea(si, rt::sample1D(5, i, 0, 0, 0), rt::sample1D(5, i, 0, 0, 1), rt::sample1D(5, i, 0, 0, 2), ls));
    // Recover the triangle and distance along wi, as a BSDF-sampled ray hitting it would.
    const float t = (2.0f - si.position.y) / ls.wi.y;
    const glm::vec3 q = si.position + t * ls.wi;
    const uint32_t tri = q.x < 1.5f ? 2u : 3u;
    ++count[tri - 2];
    CHECK(ls.pdf == doctest::Approx(lights.areaPdf(tri, t, ls.wi.y)).epsilon(1e-3));
    CHECK(ls.radiance.x == doctest::Approx(2.0f / ls.pdf).epsilon(1e-4));
  }
  // Picked by power (emission x area): the larger triangle twice as often, within sampling noise.
  CHECK(count[1] > count[0] * 3 / 2);
  CHECK(count[1] < count[0] * 3);
}
