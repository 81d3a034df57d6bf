// Image-space partitioning: one task per tile, the scene counted as one broadcast per PE, the
// cost pre-pass feeding cost-driven schedules, adaptive subdivision adding tasks but not
// changing the image.
#include <algorithm>

#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

namespace {

struct Fixture {
  scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  scene::Camera cam = scene::selectCamera(s, "", 1.0f);
};

}  // namespace

TEST_CASE("ImageSpace: one task per tile and one scene broadcast per PE") {
  Fixture f;
  rt::TraceOptions opt;
  opt.integrator.kind = rt::IntegratorKind::Whitted;
  opt.tileSizePx = 8;
  par::Runtime runtime(3, "demand");
  const rt::TraceResult r = rt::renderRays(f.s, f.cam, 40, 20, opt, "image-space", runtime);
  CHECK(r.tasks == 5u * 3u);  // ceil(40/8) x ceil(20/8)
  const par::RunRecord& rec = runtime.record();
  REQUIRE(rec.stages.size() == 1);
  uint64_t tasks = 0;
  for (const par::PeStageRecord& pe : rec.stages[0].pes) {
    tasks += pe.tasks;
    CHECK(pe.broadcastsReceived == 1u);
    CHECK(pe.broadcastBytesReceived == f.s.memoryBytes());
    CHECK(pe.bytesSent == 0u);  // world model: no ray messages
  }
  CHECK(tasks == r.tasks);
  CHECK(r.rays.cameraRays == 40u * 20u);
}

TEST_CASE("ImageSpace: cost estimates from the pre-pass reach cost-driven schedules") {
  Fixture f;
  rt::TraceOptions opt;
  opt.integrator.kind = rt::IntegratorKind::Whitted;
  opt.tileSizePx = 8;
  par::Runtime runtime(2, "hot-spots");
  rt::renderRays(f.s, f.cam, 32, 32, opt, "image-space", runtime);
  // Two stages: the cost pre-pass, then the trace whose TaskSet carries the estimates.
  REQUIRE(runtime.record().stages.size() == 2);
  CHECK(runtime.record().stages[0].name == "cost pre-pass");
  const std::vector<par::TaskInfo>& tasks = runtime.record().stages[1].tasks;
  REQUIRE(tasks.size() == 16u);
  double lo = tasks[0].costEstimate, hi = lo;
  for (const par::TaskInfo& t : tasks) lo = std::min(lo, t.costEstimate), hi = std::max(hi, t.costEstimate);
  // Tiles over the glass sphere trace many more rays than tiles over a wall.
  CHECK(hi > 1.5 * lo);
}

TEST_CASE("ImageSpace: adaptive subdivision splits expensive tiles and keeps the image") {
  Fixture f;
  rt::TraceOptions opt;
  opt.integrator.kind = rt::IntegratorKind::Whitted;
  opt.tileSizePx = 16;
  par::Runtime plainRt(2, "demand");
  const rt::TraceResult plain = rt::renderRays(f.s, f.cam, 64, 64, opt, "image-space", plainRt);
  opt.adaptive = true;
  par::Runtime adaptiveRt(2, "demand");
  const rt::TraceResult adaptive = rt::renderRays(f.s, f.cam, 64, 64, opt, "image-space", adaptiveRt);
  CHECK(plain.tasks == 16u);
  CHECK(adaptive.tasks > plain.tasks);
  CHECK(adaptive.image.pixels == plain.image.pixels);
}
