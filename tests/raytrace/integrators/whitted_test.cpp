// Whitted integrator: direct light from a point light follows the inverse-square cosine law;
// mirrors are followed exactly up to --max-depth and no further.
#include <cmath>

#include <doctest/doctest.h>

#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partition.h"

using namespace pr;

namespace {

rt::TraceResult render(const scene::Scene& s, const scene::Camera& c, int w, int h, rt::IntegratorKind kind, int spp,
                       int maxDepth) {
  rt::TraceOptions opt;
  opt.integrator.kind = kind;
  opt.integrator.spp = spp;
  opt.integrator.maxDepth = maxDepth;
  par::Runtime runtime(1);
  return rt::renderRays(s, c, w, h, opt, "sequential", runtime);
}

}  // namespace

TEST_CASE("Whitted: a diffuse plane under a point light follows the inverse-square cosine law") {
  // Analytic expectation: L = albedo / pi * I * cos(theta) / d^2 with cos(theta) = height / d,
  // for a light of intensity I at `height` above the point. Each pixel is the mean of that
  // over its footprint; the reference integrates it with an 8x8 midpoint rule, the render
  // with 16 stratified samples. Both errors are far below the 1% tolerance (L changes by at
  // most 5% across a pixel, smoothly).
  const float albedo = 0.5f, intensity = 10.0f, height = 2.0f, ymag = 2.0f;
  const int size = 32;
  scene::Scene s;
  const uint32_t mat = test::addMaterial(s, test::diffuse(albedo));
  test::addGround(s, 10.0f, mat);
  scene::PunctualLight light;
  light.position = glm::vec3(0.0f, height, 0.0f);
  light.intensity = intensity;
  s.lights.push_back(light);
  const scene::Camera cam = test::topDownOrtho(5.0f, ymag);
  for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
    CAPTURE(rt::toString(kind));
    const rt::TraceResult r = render(s, cam, size, size, kind, 16, 1);
    double worst = 0.0;
    for (int y = 0; y < size; y += 3)
      for (int x = 0; x < size; x += 3) {
        double expected = 0.0;
        for (int j = 0; j < 8; ++j)
          for (int i = 0; i < 8; ++i) {
            const double wx = (2.0 * (x + (i + 0.5) / 8.0) / size - 1.0) * ymag;
            const double wz = -(1.0 - 2.0 * (y + (j + 0.5) / 8.0) / size) * ymag;
            const double d2 = wx * wx + wz * wz + height * height;
            expected += albedo / M_PI * intensity * (height / std::sqrt(d2)) / d2 / 64.0;
          }
        worst = std::max(worst, std::fabs(r.image.at(x, y).x / expected - 1.0));
      }
    CHECK(worst < 0.01);
  }
}

TEST_CASE("Whitted: a closed mirror ball is followed exactly max-depth bounces and no further") {
  scene::Scene s;
  scene::Material mirror;
  mirror.metallicFactor = 1.0f;
  mirror.roughnessFactor = 0.0f;
  const uint32_t mat = test::addMaterial(s, mirror);
  test::addSphere(s, glm::vec3(0.0f), 3.0f, 12, mat);
  scene::PunctualLight light;
  light.intensity = 1.0f;
  s.lights.push_back(light);
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.5f, 0.2f, 0.1f), 1.0f);
  for (int depth : {1, 5, 40}) {
    const rt::TraceResult r = render(s, cam, 8, 8, rt::IntegratorKind::Whitted, 1, depth);
    // A white mirror reflects everything (Schlick F = 1) and the closed ball never lets a ray
    // out, so each camera ray is followed by exactly `depth` reflections: hits at depth
    // 0 .. depth-1 spawn one each, the hit at depth `depth` only adds emission.
    CHECK(r.rays.cameraRays == 64u);
    CHECK(r.rays.continuationRays == 64u * uint64_t(depth));
  }
}
