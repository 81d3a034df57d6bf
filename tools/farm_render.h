// `parrender render --farm`: the image-space ray tracer (every integrator, the photon map's
// pre-passes included) as Jensen's render farm (common/parallel/farm/farm.h). Under
// `mpirun --enable-recovery -np N`, rank 0 is the master: it hands out screen areas (jobs) in
// the order of --farm-schedule, assembles the image as results arrive and rewrites it every
// --farm-refresh seconds; every other rank is a server with --threads PEs of its own, which runs
// the pre-passes itself from the same seed (so every server holds the same photon maps and
// irradiance cache, and the image is bit-identical to a single process's) - or, with
// --farm-prepass shared, runs them as one computation across the servers (each its share, the
// results all-gathered, as the runtime across processes does) - and renders each job as a stage
// of its own runtime, its tiles ordered by --schedule among its PEs.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "common/image/image.h"
#include "common/parallel/farm/farm_replay.h"
#include "common/parallel/run_options.h"
#include "tools/render_methods.h"
#include "tools/timed_render.h"

namespace pr::cli {

struct FarmArgs {
  bool enabled = false;
  std::string job = "32x24";  // the seed's photon-map farm used 32x24 and 40x30
  std::string schedule = "demand";
  double deadlineSeconds = 30.0;
  double refreshSeconds = 2.0;
  int jobsAhead = 2;
  bool progress = false;
  std::string statusFile;  // --farm-status: the run's exit status, written by rank 0 at the end
  std::string prepass = "replicated";  // --farm-prepass: replicated | shared
};
// What a farm is: --farm (described as `what`), --farm-job, --farm-schedule, --farm-prepass,
// --farm-deadline, --farm-ahead (render, compare, report).
void addFarmOptions(CLI::App& command, FarmArgs& args, const std::string& what);
// What only `render --farm` watches: --farm-refresh, --farm-status, --progress.
void addFarmRenderOptions(CLI::App& command, FarmArgs& args);

// Bad use, refused before the scene is loaded (pr::InputError naming the reason): one rank only
// (no mpirun), a method other than image-space (a server must hold all a job needs), a
// master's schedule that needs cost estimates, --adaptive, a malformed job size.
// With --farm-status, has rank 0 write the run's exit status to that file as the run ends
// (ProcessGroup::atVerdict): mpirun --enable-recovery exits 0 whatever the ranks' status.
void reportFarmStatus(const FarmArgs& farm);

void checkFarm(const FarmArgs& farm, const RenderMethod& method, const RenderSettings& settings, int ranks);

// The render as a farm, on every rank: the master's image is written to `output` every
// --farm-refresh seconds and at the end (none when `output` is empty). On rank 0 returns the
// image and the farm's run record, whose PEs are the servers; elsewhere nothing. Marks lost
// servers in the ProcessGroup, so the run's ending does not wait for them.
struct FarmInput {
  const scene::Scene& scene;
  const scene::Camera& camera;
  const scene::RenderPlan& plan;
  int width = 0, height = 0;
  const RenderSettings& settings;
  par::ScheduleOptions schedule;  // among each server's PEs
  int threads = 1;                // each server's PEs
};
struct FarmRender {
  par::RunRecord record;
  image::Image image;
};
FarmRender renderOnFarm(const FarmArgs& farm, const FarmInput& input, const std::string& output);

// On rank 0: a warning on stderr when mpirun was not given --enable-recovery, without which a
// server that dies ends every rank.
void warnWithoutRecovery();

// The farm as one of the timed renders of compare and report (every rank takes part): the
// master's wall clock around the farm, the CPU time of the master and of every server (each
// reports its own as it says goodbye). Those commands measure the farm and need every rank for
// the renders after it, so a server lost during it ends the run (status 1) with one message;
// `render --farm` is the farm that goes on without it.
TimedRender timedFarmRender(const FarmArgs& farm, const RenderInput& input, const RenderSettings& settings, int threads,
                            const par::ScheduleOptions& schedule);

// A farm's run record (renderOnFarm) replayed at `servers` servers on `network`, its jobs
// ordered by `schedule` (common/parallel/farm/farm_replay.h). Throws pr::InputError for a
// record without its jobs stage.
par::FarmPrediction predictFarmRun(const par::RunRecord& record, int servers, const par::NetworkModel& network,
                                   const std::string& schedule, const par::ScheduleParams& params);

// The farm's lines of a summary: jobs, servers, their jobs, CPU, busy and idle time, the lost
// ones, results sent ("" for a record that is not a farm's).
std::string farmSummary(const par::RunRecord& record);

}  // namespace pr::cli
