// The rasterizer's share of the material features: image-based lighting of the environment
// (exact under a uniform one, SH irradiance of a non-uniform one against its closed form), the
// environment as background, KHR_materials_specular 0 as pure Lambert, alpha MASK cutting
// fragments (the surface behind shows), BLEND keeping a fraction alpha of them, the same in
// every sort point.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "common/parallel/runtime.h"
#include "raster/parallel_pipeline.h"
#include "raster/raster_test_scenes.h"
#include "raster/sequential_pipeline.h"
#include "raster/stages/image_based_light.h"

using namespace pr;
using namespace pr::raster;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Two full-screen quads seen by the pixel camera: a red one at z = 1 (material 1) in front of a
// green one at z = 0 (material 2), lit from the eye by a directional light.
scene::Scene layered(scene::AlphaMode mode, float alpha) {
  scene::Scene s = test::emptyScene();
  scene::Material red = s.materials[0], green = s.materials[0];
  red.baseColorFactor = glm::vec4(1, 0, 0, alpha);
  red.alphaMode = mode;
  green.baseColorFactor = glm::vec4(0, 1, 0, 1);
  s.materials.push_back(red);
  s.materials.push_back(green);
  for (auto [z, m] : {std::pair{1.0f, 1u}, std::pair{0.0f, 2u}}) {
    test::addTriangle(s, {-20, -20, z}, {20, -20, z}, {20, 20, z}, m);
    test::addTriangle(s, {-20, -20, z}, {20, 20, z}, {-20, 20, z}, m);
  }
  scene::PunctualLight sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::vec3(0, 0, -1);
  sun.intensity = 1.0f;
  s.lights.push_back(sun);
  return s;
}

int count(const RegionFramebuffer& fb, int channel) {
  int n = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) n += fb.colour(x, y)[channel] > 0.1f ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("RasterMaterials: a uniform environment lights a white Lambertian surface with exactly its radiance") {
  scene::Scene s = test::emptyScene();
  s.materials[0].baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  s.materials[0].specularFactor = 0.0f;  // KHR_materials_specular 0: pure Lambert
  test::addTriangle(s, {-4, -4, 0}, {4, -4, 0}, {4, 4, 0});
  s.environment = std::make_shared<const scene::Environment>(scene::Environment::uniform(glm::vec3(2.0f), "test"));
  RasterStats stats;
  const RegionFramebuffer fb = renderSequential(s, test::pixelOrthoCamera(16), 16, 16, {}, &stats);
  CHECK_FALSE(stats.usesHeadlight);
  // irradiance pi L, times rho / pi
  CHECK(fb.colour(9, 9).x == doctest::Approx(1.0f).epsilon(1e-5));
  // An uncovered pixel shows the environment, as a ray tracer's escaping camera ray does.
  CHECK(fb.colour(1, 1) == glm::vec3(2.0f));
  // --headlight instead: the same surface lit from the eye, the background black.
  SequentialOptions headlight;
  headlight.headlight = true;
  const RegionFramebuffer h = renderSequential(s, test::pixelOrthoCamera(16), 16, 16, headlight, &stats);
  CHECK(stats.usesHeadlight);
  CHECK(h.colour(1, 1) == glm::vec3(0.0f));
}

TEST_CASE("RasterMaterials: SH irradiance of a sky that brightens upwards matches its closed form") {
  // L(d) = a + b d.y gives E(n) = pi a + (2 pi / 3) b n.y (the cosine lobe's first two bands).
  const float a = 1.0f, b = 0.8f;
  const int w = 256, h = 128;
  image::Image sky(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) sky.at(x, y) = glm::vec3(a + b * std::cos(kPi * (float(y) + 0.5f) / float(h)));
  const scene::Environment env = scene::Environment::fromImage(sky, 1.0f, 0.0f, "sky");
  const ImageBasedLight ibl(env);
  for (glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(1, 1, 0))}) {
    CAPTURE(n.y);
    CHECK(ibl.irradiance(n).x == doctest::Approx(kPi * a + 2.0f * kPi / 3.0f * b * n.y).epsilon(0.01));
  }
  // Prefiltered radiance along +y: the sky's value there, blurred more with roughness but
  // always between the darkest and brightest radiance.
  CHECK(ibl.prefiltered(glm::vec3(0, 1, 0), 0.0f).x == doctest::Approx(a + b).epsilon(0.02));
  CHECK(ibl.prefiltered(glm::vec3(0, 1, 0), 1.0f).x < ibl.prefiltered(glm::vec3(0, 1, 0), 0.0f).x);
  CHECK(ibl.prefiltered(glm::vec3(0, 1, 0), 1.0f).x > a);
  // The split-sum albedo of a smooth lobe at normal incidence is F0 A + F90 B ~ F0.
  const glm::vec2 ab = specularAlbedo(1.0f, 0.05f);
  CHECK(ab.x + ab.y == doctest::Approx(1.0f).epsilon(0.03));
}

TEST_CASE("RasterMaterials: MASK cuts fragments below the cutoff, BLEND keeps a fraction alpha, in every sort point") {
  const FrameView view = makeFrameView(test::pixelOrthoCamera(32), 32, 32);
  // MASK with alpha 0.3 under the default cutoff 0.5: the green quad behind shows everywhere.
  const RegionFramebuffer masked = renderSequential(layered(scene::AlphaMode::Mask, 0.3f), test::pixelOrthoCamera(32), 32, 32);
  CHECK(count(masked, 0) == 0);
  CHECK(count(masked, 1) == 32 * 32);
  // Above the cutoff the red quad is opaque.
  CHECK(count(renderSequential(layered(scene::AlphaMode::Mask, 0.6f), test::pixelOrthoCamera(32), 32, 32), 0) == 32 * 32);
  // BLEND alpha 0.25: about a quarter red (1024 pixels: 3 sigma = 42), the rest green.
  const scene::Scene blend = layered(scene::AlphaMode::Blend, 0.25f);
  const RegionFramebuffer seq = renderSequential(blend, test::pixelOrthoCamera(32), 32, 32);
  CHECK(std::abs(count(seq, 0) - 256) < 42);
  CHECK(count(seq, 0) + count(seq, 1) == 32 * 32);
  for (const char* method : {"sort-first", "sort-middle", "sort-last"}) {
    CAPTURE(method);
    par::Runtime rt(2);
    SortOptions o;
    o.tileSizePx = 8;
    CHECK(identical(renderParallel(blend, view, method, o, rt), seq));
  }
}
