// One fresh, timed render as the commands that compare renders take it (sweep, compare,
// report): a new runtime with P PEs and the schedule, the wall clock around the method, the
// CPU time of the whole process (every PE), the outcome and the run record it left.
#pragma once

#include <functional>

#include "common/parallel/run_options.h"
#include "common/parallel/run_record.h"
#include "common/scene/camera.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
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

// User plus system CPU seconds of this process so far.
double processCpuSeconds();

TimedRender timedRender(const RenderMethod& method, const RenderInput& input, const RenderSettings& settings, int pes,
                        const par::ScheduleOptions& schedule, std::function<void(int64_t, int64_t)> progress = {});

}  // namespace pr::cli
