// Image-space partitioning: one task per tile, the scene and BVH counted as one broadcast per
// PE, finished tiles counted as results sent to the assembler, the
// cost pre-pass feeding cost-driven schedules, adaptive subdivision adding tasks but not
// changing the image.
#include <algorithm>

#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/core/bvh.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

namespace {

struct Fixture {
  scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  scene::Camera cam = scene::selectCamera(s, "", 1.0f);
};

}  // namespace

TEST_CASE("ImageSpace: the BVH built in its own stage, one task per tile, scene and BVH broadcast, tiles sent to the assembler") {
  Fixture f;
  rt::TraceOptions opt;
  opt.integrator.kind = rt::IntegratorKind::Whitted;
  opt.tileSizePx = 8;
  par::Runtime runtime(3, "balanced");
  const rt::TraceResult r = rt::renderRays(f.s, f.cam, 40, 20, opt, "image-space", runtime);
  CHECK(r.tasks == 5u * 3u);  // ceil(40/8) x ceil(20/8)
  const par::RunRecord& rec = runtime.record();
  REQUIRE(rec.stages.size() == 2);
  CHECK(rec.stages[0].name == "build");
  CHECK(rec.stages[0].pes[0].tasks == 1u);  // on the assembler's PE
  const par::StageRecord& trace = rec.stages[1];
  CHECK(trace.name == "trace");
  const uint64_t bvhBytes = rt::Bvh(f.s, opt.bvh).stats().memoryBytes;
  uint64_t tasks = 0;
  for (const par::PeStageRecord& pe : trace.pes) {
    tasks += pe.tasks;
    const bool root = &pe == &trace.pes[0];  // PE 0 loaded the scene and built the BVH
    CHECK(pe.broadcastsReceived == (root ? 0u : 1u));
    CHECK(pe.broadcastBytesReceived == (root ? 0u : f.s.memoryBytes() + bvhBytes));
    CHECK(pe.bytesReceived == (&pe == &trace.pes[0] ? 11680u : 0u));
  }
  CHECK(tasks == r.tasks);
  CHECK(r.rays.cameraRays == 40u * 20u);
  // Balanced: PE 0 renders tiles 0-4 (row 0), PE 1 tiles 5-9 (8x8 each), PE 2 tiles 10-14
  // (8x4, the last row). Every tile not rendered on PE 0 travels to it as one film block of a
  // 16-byte rectangle and 3 int64 sums per pixel: PE 1 5 x (16 + 24 * 64) = 7760 bytes, PE 2
  // 5 x (16 + 24 * 32) = 3920 bytes, and no ray messages at all (world model).
  CHECK(trace.pes[0].messagesSent == 0u);
  CHECK(trace.pes[1].messagesSent == 5u);
  CHECK(trace.pes[1].bytesSent == 7760u);
  CHECK(trace.pes[2].messagesSent == 5u);
  CHECK(trace.pes[2].bytesSent == 3920u);
  REQUIRE(trace.channels.size() == 1u);
  CHECK(trace.channels[0].kind == "results");
  CHECK(trace.channels[0].bytes == 11680u);
}

TEST_CASE("ImageSpace: cost estimates from the pre-pass reach cost-driven schedules") {
  Fixture f;
  rt::TraceOptions opt;
  opt.integrator.kind = rt::IntegratorKind::Whitted;
  opt.tileSizePx = 8;
  par::Runtime runtime(2, "hot-spots");
  rt::renderRays(f.s, f.cam, 32, 32, opt, "image-space", runtime);
  // The build, the cost pre-pass, then the trace whose TaskSet carries the estimates.
  REQUIRE(runtime.record().stages.size() == 3);
  CHECK(runtime.record().stages[1].name == "cost pre-pass");
  const std::vector<par::TaskInfo>& tasks = runtime.record().stages[2].tasks;
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
