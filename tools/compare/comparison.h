// A comparison run: every valid combination of methods, P, schedules, integrators (ray
// tracers) and compositors (sort-last) rendered afresh and timed N times on one scene, each
// checked against the other images of its family (the project promises them bit-identical:
// a ray tracer's image depends only on its integrator and settings, a rasterizer's on nothing
// but the scene) and measured against the path-traced reference. Wall and CPU time are medians over
// the repeats; every other figure of a row is read from the run record of its median run (the
// lower middle one for an even count) through common/parallel/metrics.h. Used by
// `parrender compare` (cmd_compare.cpp) and `parrender report` (cmd_report.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/image/image.h"
#include "common/parallel/metrics.h"
#include "common/parallel/run_options.h"
#include "common/parallel/run_record.h"
#include "tools/farm_render.h"
#include "tools/render_methods.h"
#include "tools/sweep/path_reference.h"
#include "tools/timed_render.h"

namespace pr::cli {

// "-" marks a dimension that does not apply to the method (integrator of a rasterizer,
// compositor of anything but sort-last).
inline constexpr const char* kNotApplicable = "-";

struct Combination {
  std::string method;
  MethodFamily family = MethodFamily::Ray;
  std::string schedule, integrator, compositor;
  int pes = 1;
  int ranks = 1;  // under mpirun: every rank (P = ranks x PEs per rank), or 1 for rank 0 alone
  // A farm (farm_render.h): the master's order of jobs; empty for every other render. A farm's
  // P counts its servers' PEs, (ranks - 1) x PEs per server; `schedule` is among each server's.
  std::string farm;
  std::string label() const;  // "object-space demand path P=2", "... P=4 R=2" across ranks,
                              // "image-space farm(demand) demand path P=2 R=3"
  std::string methodName() const;  // "image-space", or "image-space farm" for a farm
  // The PEs each process that renders has: P / ranks, or for a farm P / its servers.
  int pesPerProcess() const { return farm.empty() ? pes / ranks : pes / (ranks - 1); }
};

struct ComparisonSpec {
  std::vector<std::string> methods, schedules, integrators, compositors;
  std::vector<int> threads;  // values of P; under mpirun, PEs per rank (P = ranks x each)
  bool oneRankBaseline = true;  // under mpirun, also P = 1 on rank 0 alone
  int repeat = 3;
  RenderSettings settings;       // every other option of the renders
  par::ScheduleParams scheduleParams;
  bool reference = true;         // measure RMSE against the path-traced reference
  ReferenceSettings referenceSettings;
  bool keepImages = true;        // keep each row's image (report); else only the figures
  bool progress = true;          // a line on stderr per render
  std::vector<std::string> notes;  // options given that some methods do not take (shown as skipped)
  // With farm.enabled, under mpirun: image-space also as a farm, a master and ranks - 1 servers
  // of each --threads value, for every schedule (among a server's PEs) and integrator, after
  // every other render.
  FarmArgs farm;
};

struct ComparisonRow {
  Combination what;
  std::vector<double> wallSeconds, cpuSeconds;  // one per repeat
  double wall = 0.0, wallMin = 0.0, wallMax = 0.0, cpu = 0.0;  // medians over the repeats, and the spread
  double speedup = 0.0;        // T1/Tn against the same combination at P = 1; 0 when not run
  double speedupSerial = 0.0;  // Ts/Tn against the family's serial reference; 0 when not run
  double efficiency = 0.0;     // speedup / P; 0 when T1 unknown
  std::string serialReference; // the label of the run giving Ts
  par::RunSummary summary;     // of the median run
  par::RunRecord record;       // the median run's record
  double cacheHitRatio = -1.0; // hits / uses of a data manager's cache; < 0 when none ran
  std::uint64_t rays = 0;
  std::string effects;         // which of the plan's effects the method simulated (RenderOutcome::effects)
  double rmse = -1.0;          // against the path-traced reference; < 0 without one
  bool agrees = true;          // bit-identical to its family's first image
  std::string agreement;       // "reference", "identical", or what differs from which run
  image::Image image;          // kept with keepImages
};

struct SkippedCombination {
  std::string what, reason;
};

struct Comparison {
  std::vector<ComparisonRow> rows;
  std::vector<SkippedCombination> skipped;
  Reference reference;  // empty image without one
  int mismatches = 0;   // rows whose image differs from their family's
};

// Throws pr::InputError for an empty dimension or an unknown name, and for a farm without a
// server or the farm's bad use (checkFarm); a combination that cannot
// run (a one-PE reference, sequential or sequential-raster, at P > 1; binary-swap at P not a power of two, a request over the memory
// limit) is skipped with the reason. Under mpirun with R ranks, each value T of spec.threads
// gives a row at P = R x T across every rank, and every combination also runs at P = 1 on
// rank 0 alone, the other ranks waiting (unless !oneRankBaseline): its T1 and the family's
// Ts. Every rank runs the same renders; only rank 0's Comparison holds figures and images
// (holdsResults()).
Comparison runComparison(const ComparisonSpec& spec, const RenderInput& input);

// The message kinds in the order the table and files list them.
const std::vector<std::string>& comparisonKinds();

// A row's traffic of one kind (nullptr when none), and of every kind together.
const par::KindTraffic* kindTraffic(const ComparisonRow& row, const std::string& kind);
par::KindTraffic allTraffic(const ComparisonRow& row);
// A named per-PE counter of the row's run, summed over the PEs (0 when the run has none).
double counterTotal(const ComparisonRow& row, const std::string& name);

// The default values of --threads: 1, 2, 4, ... up to this machine's cores, and the core count
// itself; under mpirun, one PE per rank.
std::vector<int> defaultThreadCounts();

}  // namespace pr::cli
