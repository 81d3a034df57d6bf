// Both families on the shared models as users bring them (no lights: the default uniform
// environment): the rasterizer covers exactly the pixels whose centre ray hits the ray
// tracers' geometry (but for back faces of single-sided materials, which it culls), and the path tracer's image mean at 16 spp is within 2 % of an
// independent 1024-spp reference (no bias from the MIS, layering, normal-map and alpha code).
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "raster/sequential_pipeline.h"
#include "raster/stages/depth_resolve.h"
#include "raytrace/core/bvh.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

namespace {

const char* const kModels[] = {
    "Duck/glTF-Binary/Duck.glb",
    "Avocado/glTF/Avocado.gltf",
    "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
    "NormalTangentTest/glTF-Binary/NormalTangentTest.glb",
    "SpecularTest/glTF-Binary/SpecularTest.glb",
    "ClearCoatTest/glTF-Binary/ClearCoatTest.glb",
    "SheenCloth/glTF/SheenCloth.gltf",
    "VertexColorTest/glTF-Binary/VertexColorTest.glb",
};

scene::Scene load(const char* model) {
  setQuiet(true);
  scene::Scene s = scene::loadGltf(test::sharedScenes() / model);
  setQuiet(false);
  s.environment = std::make_shared<const scene::Environment>(scene::Environment::uniform(glm::vec3(1.0f), "test"));
  return s;
}

bool backFaceOfSingleSided(const scene::Scene& s, const rt::Hit& hit, const rt::Ray& ray) {
  const scene::Triangle& t = s.triangles[hit.triangle];
  const glm::vec3 n = glm::cross(s.positions[t.v[1]] - s.positions[t.v[0]], s.positions[t.v[2]] - s.positions[t.v[0]]);
  return !s.materials[t.material].doubleSided && glm::dot(n, ray.direction) > 0.0f;
}

double mean(const image::Image& img) {
  double sum = 0.0;
  for (const glm::vec3& p : img.pixels) sum += double(p.x + p.y + p.z);
  return sum / (3.0 * double(img.pixels.size()));
}

}  // namespace

TEST_CASE("FamilyAgreement: raster coverage is the ray tracers' primary-hit coverage at pixel centres") {
  if (!test::haveSharedScenes()) return;
  constexpr int kN = 96;
  for (const char* model : kModels) {
    CAPTURE(std::string(model));
    const scene::Scene s = load(model);
    const scene::Camera camera = scene::selectCamera(s, "", 1.0f);
    const raster::FrameView view = raster::makeFrameView(camera, kN, kN);
    const raster::RegionFramebuffer fb = raster::renderSequential(s, camera, kN, kN);
    const rt::Bvh bvh(s);
    const glm::mat4 inverse = glm::inverse(view.viewProjection);
    int covered = 0, disagree = 0, culled = 0;
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) {
        // The pixel centre's view ray, from the near plane (the rasterizer's clip) outwards.
        const float nx = 2.0f * (float(x) + 0.5f) / kN - 1.0f, ny = 1.0f - 2.0f * (float(y) + 0.5f) / kN;
        const glm::vec4 a = inverse * glm::vec4(nx, ny, -1.0f, 1.0f), b = inverse * glm::vec4(nx, ny, 0.5f, 1.0f);
        const glm::vec3 o = glm::vec3(a) / a.w;
        const rt::Ray ray{o, 0.0f, glm::normalize(glm::vec3(b) / b.w - o), rt::kInfinity};
        rt::Hit hit;
        const bool hits = bvh.intersect(ray, hit);
        const bool rasterCovers = raster::keyCovered(fb.key(x, y));
        covered += rasterCovers ? 1 : 0;
        // The rasterizer culls the back faces of single-sided materials, as glTF asks; the ray
        // tracers see both sides of every surface. Those pixels are counted apart.
        if (hits && !rasterCovers && backFaceOfSingleSided(s, hit, ray)) {
          ++culled;
          continue;
        }
        disagree += hits != rasterCovers ? 1 : 0;
      }
    CAPTURE(covered);
    CAPTURE(disagree);
    CAPTURE(culled);
    CHECK(covered > kN * kN / 20);
    // Only pixels whose centre lies on a silhouette edge, up to rounding, may differ.
    CHECK(disagree <= kN * kN / 200);
  }
}

TEST_CASE("FamilyAgreement: the path tracer's mean is within 2% of a long independent reference") {
  if (!test::haveSharedScenes()) return;
  constexpr int kN = 24;
  for (const char* model : kModels) {
    CAPTURE(std::string(model));
    const scene::Scene s = load(model);
    const scene::Camera camera = scene::selectCamera(s, "", 1.0f);
    auto render = [&](int spp, uint64_t seed) {
      rt::TraceOptions o;
      o.integrator.kind = rt::IntegratorKind::Path;
      o.integrator.spp = spp;
      o.integrator.seed = seed;
      par::Runtime runtime(2);
      return rt::renderRays(s, camera, kN, kN, o, "image-space", runtime).image;
    };
    const double quick = mean(render(16, 7)), reference = mean(render(1024, 12345));
    CAPTURE(quick);
    CAPTURE(reference);
    CHECK(reference > 0.02);
    CHECK(quick == doctest::Approx(reference).epsilon(0.02));
  }
}
