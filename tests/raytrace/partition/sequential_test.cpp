// Sequential tracer: the reference every partition is compared with. It must render the
// bundled Cornell box with light where light is, finite everywhere, deterministically.
#include <algorithm>
#include <cmath>

#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

TEST_CASE("Sequential: Cornell box renders finite, lit and repeatable") {
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
    CAPTURE(rt::toString(kind));
    rt::TraceOptions opt;
    opt.integrator.kind = kind;
    opt.integrator.spp = 1;
    par::Runtime rt1(1);
    const rt::TraceResult a = rt::renderRays(s, cam, 24, 24, opt, "sequential", rt1);
    par::Runtime rt2(2);
    const rt::TraceResult b = rt::renderRays(s, cam, 24, 24, opt, "sequential", rt2);
    CHECK(a.image.pixels == b.image.pixels);
    CHECK(a.rays.cameraRays == 24u * 24u);
    CHECK(a.rays.shadowRays > 0u);
    double sum = 0.0;
    for (const glm::vec3& p : a.image.pixels) {
      REQUIRE((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
      sum += p.x + p.y + p.z;
    }
    CHECK(sum > 0.0);
    // The light quad (radiance 30, scenes/README.md) is seen directly in the upper half; with
    // one sample per pixel a pixel sees all of it or none of it.
    float brightest = 0.0f;
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 24; ++x) brightest = std::max(brightest, a.image.at(x, y).y);
    CHECK(brightest >= 30.0f);
  }
}

TEST_CASE("Sequential: the seed selects the random streams, the same seed gives the same image") {
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell-diffuse.gltf");
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  auto render = [&](uint64_t seed) {
    rt::TraceOptions opt;
    opt.integrator.kind = rt::IntegratorKind::Path;
    opt.integrator.seed = seed;
    par::Runtime runtime(1);
    return rt::renderRays(s, cam, 16, 16, opt, "sequential", runtime).image;
  };
  const image::Image a = render(1), b = render(1), c = render(2);
  CHECK(a.pixels == b.pixels);
  CHECK(a.pixels != c.pixels);
}
