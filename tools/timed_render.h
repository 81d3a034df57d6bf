// One fresh, timed render as the commands that compare renders take it (sweep, compare,
// report): a new runtime with P PEs and the schedule, the wall clock around the method, the
// CPU time of the whole process (every PE; every rank's, across ranks), the outcome and the
// run record it left. Under mpirun a render runs either across every rank (P = ranks x PEs
// per rank; its image and whole record on rank 0) or on rank 0 alone while the other ranks
// wait (the one-PE baselines), whose TimedRender elsewhere is empty.
#pragma once

#include <functional>
#include <string>

#include "common/parallel/run_options.h"
#include "common/parallel/run_record.h"
#include "common/scene/camera.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
#include "common/util/cpu_time.h"
#include "tools/render_methods.h"

namespace pr::cli {

// What stays the same over a series of renders of one scene.
struct RenderInput {
  const scene::Scene& scene;
  const scene::Camera& camera;
  const scene::RenderPlan& plan;
  int width = 0, height = 0;
};

struct TimedRender {
  RenderOutcome outcome;
  par::RunRecord record;
  double wallSeconds = 0.0, cpuSeconds = 0.0;
};


// Where a render runs: `pes` PEs in all, on `ranks` ranks - 1 (this process; under mpirun,
// rank 0 alone) or every rank of the run (ProcessGroup::ranks(), which must divide pes).
struct Placement {
  int pes = 1, ranks = 1;
  // " (R ranks x T PEs)" across ranks, else empty: what a summary line adds to "P N".
  std::string acrossRanks() const;
};

// T PEs on every rank of the run: P = T without mpirun, R x T under it.
Placement everyRank(int threadsPerRank);

// Whether the render's figures and image are this process's to use: rank 0's, or any render
// on one rank without mpirun.
bool holdsResults();

TimedRender timedRender(const RenderMethod& method, const RenderInput& input, const RenderSettings& settings,
                        Placement where, const par::ScheduleOptions& schedule,
                        std::function<void(int64_t, int64_t)> progress = {});

}  // namespace pr::cli
