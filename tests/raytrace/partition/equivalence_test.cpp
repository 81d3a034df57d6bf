// Equivalence of the ray tracers: every partition, at every P and with every schedule, gives
// the image of the sequential tracer at P = 1 bit for bit (shared/DESIGN.md rule 3), because
// all of them move the same RayMessages through the same Integrator and the film sums in fixed
// point. One table: (scene x integrator) rows, each rendered by every (partition, P, schedule).
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "common/parallel/schedulers/scheduler.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

namespace {

constexpr int kWidth = 48, kHeight = 36;
const int kPes[] = {1, 2, 3, 4, 8};

struct Row {
  std::filesystem::path file;
  rt::IntegratorKind kind;
  int spp;
  std::vector<std::string> partitions;  // compared with sequential at P = 1
};

image::Image renderWith(const scene::Scene& s, const rt::Bvh& bvh, const scene::Camera& cam, const Row& row,
                        std::string_view partition, int pes, const std::string& schedule) {
  rt::TraceOptions opt;
  opt.integrator.kind = row.kind;
  opt.integrator.spp = row.spp;
  opt.integrator.maxDepth = 6;
  opt.integrator.seed = 11;
  opt.tileSizePx = 8;
  opt.worldBvh = &bvh;  // built once per scene; partitions that own geometry build their own
  par::Runtime runtime(pes, schedule);
  return rt::renderRays(s, cam, kWidth, kHeight, opt, partition, runtime).image;
}

// Every schedule of the registry at the given P (all of kPes when 0), or `schedules` only
// when given.
void checkRow(const Row& row, int onlyPes = 0, const std::vector<std::string>& schedules = {}) {
  const scene::Scene s = scene::loadGltf(row.file);
  const rt::Bvh bvh(s);
  const scene::Camera cam = scene::selectCamera(s, "", float(kWidth) / float(kHeight));
  const image::Image reference = renderWith(s, bvh, cam, row, "sequential", 1, "demand");
  std::vector<std::string> names = schedules;
  if (names.empty())
    for (const par::ScheduleInfo& info : par::schedules()) names.emplace_back(info.name);
  for (const std::string& partition : row.partitions)
    for (int pes : kPes)
      for (const std::string& schedule : names) {
        if (onlyPes != 0 && pes != onlyPes) continue;
        CAPTURE(partition);
        CAPTURE(pes);
        CAPTURE(schedule);
        const image::Image img = renderWith(s, bvh, cam, row, partition, pes, schedule);
        CHECK(img.pixels == reference.pixels);
      }
}

std::filesystem::path bundled(const char* name) { return test::sourceDir() / "scenes" / name; }

}  // namespace

// One test case per (row, P) keeps each under a second.
#define EQUIVALENCE_AT_EVERY_P(TITLE, ...)                              \
  TEST_CASE("Equivalence: " TITLE ", P = 1") { checkRow(__VA_ARGS__, 1); } \
  TEST_CASE("Equivalence: " TITLE ", P = 2") { checkRow(__VA_ARGS__, 2); } \
  TEST_CASE("Equivalence: " TITLE ", P = 3") { checkRow(__VA_ARGS__, 3); } \
  TEST_CASE("Equivalence: " TITLE ", P = 4") { checkRow(__VA_ARGS__, 4); } \
  TEST_CASE("Equivalence: " TITLE ", P = 8") { checkRow(__VA_ARGS__, 8); }

EQUIVALENCE_AT_EVERY_P("Cornell box, Whitted, every partition and schedule = sequential",
                       Row{bundled("cornell.gltf"), rt::IntegratorKind::Whitted, 1, {"sequential", "image-space"}})
EQUIVALENCE_AT_EVERY_P("Cornell box, path tracer, every partition and schedule = sequential",
                       Row{bundled("cornell.gltf"), rt::IntegratorKind::Path, 2, {"image-space", "image-space-cached"}})
EQUIVALENCE_AT_EVERY_P("diffuse Cornell box, path tracer, every partition and schedule = sequential",
                       Row{bundled("cornell-diffuse.gltf"), rt::IntegratorKind::Path, 1, {"image-space"}})
EQUIVALENCE_AT_EVERY_P("hot-spot scene, Whitted, every partition and schedule = sequential",
                       Row{bundled("hotspot.gltf"), rt::IntegratorKind::Whitted, 1, {"image-space", "image-space-cached"}})

// Shared glTF models: textures (BoxTextured), punctual lights and transmission
// (LightsPunctualLamp), three schedules at every P.
TEST_CASE("Equivalence: shared BoxTextured, image-space = sequential at every P") {
  if (!test::haveSharedScenes()) return;
  for (rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path})
    checkRow({test::sharedScenes() / "BoxTextured/glTF/BoxTextured.gltf", kind, 1, {"image-space"}}, 0,
             {"demand", "spiral", "distributed"});
}

// Alpha-cut surfaces and an anisotropic material, whose interaction reads the material and the
// uvs: the data-managed tracer's items must cut and shade them as the whole scene does.
TEST_CASE("Equivalence: shared AlphaBlendModeTest and AnisotropyStrengthTest, image-space-cached = sequential at every P") {
  if (!test::haveSharedScenes()) return;
  for (const char* model : {"AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb", "AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb"})
    checkRow({test::sharedScenes() / model, rt::IntegratorKind::Path, 1, {"image-space-cached"}}, 0, {"demand"});
}

TEST_CASE("Equivalence: shared LightsPunctualLamp, image-space = sequential at every P") {
  if (!test::haveSharedScenes()) return;
  checkRow({test::sharedScenes() / "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", rt::IntegratorKind::Path, 1,
            {"image-space"}},
           0, {"demand", "spiral", "distributed"});
}
