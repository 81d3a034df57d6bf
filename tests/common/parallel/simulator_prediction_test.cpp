// Simulator against measurement: real renders (sort-middle rasterization, image-space and
// object-space ray tracing of the bundled Cornell box) on the thread engine at P = 1, 2 and 3,
// each record predicted at its own P on the shared-memory network, and the P = 1 record
// predicted at P = 2 and 3, compared with the measured wall times. The renderers are run here
// only to get real run records; what is tested is the simulator's model of them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>

#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "raster/parallel_pipeline.h"
#include "raster/stages/geometry.h"
#include "raytrace/partition/object_space.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

namespace {

// One render of `method` on a fresh runtime of `pes` PEs under "demand"; returns its record.
using Render = std::function<par::RunRecord(int pes)>;

struct Method {
  const char* name;
  bool fromOneClaimed;  // the P = 1 record holds all the work the method does at P > 1
  Render render;
};

par::RunRecord renderSortMiddle(const scene::Scene& s, int pes) {
  const raster::FrameView view = raster::makeFrameView(scene::selectCamera(s, "", 1.0f), 256, 256);
  raster::SortOptions options;
  options.batchSize = 128;  // 27 geometry tasks from the box's 3389 triangles
  par::Runtime rt(pes, "demand");
  for (int frame = 0; frame < 4; ++frame) raster::renderParallel(s, view, "sort-middle", options, rt);
  return rt.record();
}

rt::TraceOptions traceOptions() {
  rt::TraceOptions opt;
  opt.integrator.kind = rt::IntegratorKind::Whitted;
  opt.integrator.spp = 1;
  opt.tileSizePx = 8;
  return opt;
}

par::RunRecord renderImageSpace(const scene::Scene& s, int pes) {
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  par::Runtime rt(pes, "demand");
  rt::renderRays(s, cam, 96, 96, traceOptions(), "image-space", rt);
  return rt.record();
}

par::RunRecord renderObjectSpace(const scene::Scene& s, int pes) {
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  par::Runtime rt(pes, "demand");
  rt::ObjectSpacePartition partition(1);
  partition.render(rt::TraceJob{s, cam, 96, 96, traceOptions()}, rt);
  return rt.record();
}

double predictAt(const par::RunRecord& record, int pes) {
  par::SimOptions options;
  options.pes = pes;
  options.params.grain = record.grain;
  options.network = par::networkByName("shared-memory");
  return par::simulate(par::workloadFromRecord(record, "measured run"), "", options).wallSeconds;
}

}  // namespace

// The fastest of kRuns renders: the one least disturbed by other load on the machine.
constexpr int kRuns = 3;
par::RunRecord fastest(const Method& m, int pes) {
  par::RunRecord best = m.render(pes);
  for (int i = 1; i < kRuns; ++i) {
    par::RunRecord r = m.render(pes);
    if (r.wallSeconds < best.wallSeconds) best = std::move(r);
  }
  return best;
}

// Bounds on predicted / measured wall time, chosen from what this shared two-core machine gives
// (fastest of three runs; other builds running beside the tests):
//  - at its own P the prediction replays the record's own task spans, so it lands between 0.48
//    and 1.10 of the measurement (1.00 when undisturbed at P = 1). It is lower when the spans
//    miss time the wall holds: a PE thread waiting for a core (other load, or P = 3 on two
//    cores) at the stage start or between tasks. Bound [kLower, 1.5]: above 1.5 would mean a cost
//    counted twice, since on shared memory the model adds only 0.2 us per message.
//  - from the P = 1 record, for P <= cores and methods whose P = 1 record holds all the work of
//    every P (image-space: world model, no messages; sort-middle: its triangle messages are
//    cheap on shared memory), measured 0.50 to 0.64 at P = 2: the model assumes one free core
//    per PE, which this loaded machine does not give. Bound [kLower, 1.5].
//  - from the P = 1 record for object-space, or for P > cores: the model does not claim these
//    (a P = 1 record has no ray messages between owners, and the model assumes a core per PE),
//    so the prediction is optimistic; only the upper bound 1.5 is checked (measured 0.19-0.47).
// The lower bound is 1/10: the suite runs two tests at once (ctest -j2), under the sanitizers,
// on shared machines, and a measured wall time includes every moment the OS did not run the PE
// threads, which no model of the program sees (measured 0.14 for sort-middle at P = 3 with the
// machine's two cores busy with builds). The upper bound is the sharp one: above 1.5 a cost is
// counted twice. bench_runtime section 4 measures the same comparison on a quiet machine.
constexpr double kLower = 1.0 / 10.0, kUpper = 1.5;

TEST_CASE("Simulator: predicts measured sort-middle, image-space and object-space runs at P = 1, 2, 3") {
  setQuiet(true);
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  const Method methods[] = {
      {"sort-middle", true, [&](int p) { return renderSortMiddle(s, p); }},
      {"image-space", true, [&](int p) { return renderImageSpace(s, p); }},
      {"object-space", false, [&](int p) { return renderObjectSpace(s, p); }},
  };
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (const Method& m : methods) {
    m.render(1);  // warm caches and lazily built tables, so P = 1 is not charged for them
    const par::RunRecord one = fastest(m, 1);
    for (int pes : {1, 2, 3}) {
      const par::RunRecord measured = pes == 1 ? one : fastest(m, pes);
      const double own = predictAt(measured, pes) / measured.wallSeconds;
      const double fromOne = predictAt(one, pes) / measured.wallSeconds;
      MESSAGE(std::string(m.name) << " P=" << pes << ": measured " << measured.wallSeconds
                                  << " s; predicted / measured from its own record " << own << ", from P = 1 "
                                  << fromOne << " (" << cores << " cores)");
      CAPTURE(m.name);
      CAPTURE(pes);
      CHECK(own >= kLower);
      CHECK(own <= kUpper);
      CHECK(fromOne <= kUpper);
      if (m.fromOneClaimed && pes <= cores) CHECK(fromOne >= kLower);
    }
  }
}
