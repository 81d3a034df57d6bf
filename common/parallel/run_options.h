// The command-line face of the runtime, shared by every renderer's subcommand: --schedule NAME
// and --grain N (plus the task-manager and hybrid parameters), validated against the schedule
// registry, whose descriptions make the --help text; and --metrics FILE / --trace FILE for the
// run record. Header-only on CLI11, so only programs that parse a command line depend on it.
#pragma once

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "common/parallel/metrics.h"
#include "common/parallel/run_record.h"
#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {

struct ScheduleOptions {
  std::string schedule = "demand";  // --schedule
  ScheduleParams params;            // --grain, --buffer-depth, --static-fraction (pes is set by the caller)
};

// Adds the scheduling options to a subcommand; an unknown schedule or an out-of-range number
// is a CLI parse error (exit status 2) that lists the valid values.
inline void addScheduleOptions(CLI::App& command, ScheduleOptions& options) {
  const CLI::Validator known([](std::string& value) { return schedules().problem(value); }, "SCHEDULE");
  command.add_option("--schedule", options.schedule, "how PEs get tasks (default " + options.schedule + "):\n" + describeSchedules())
      ->check(known);
  command.add_option("--grain", options.params.grain, "tasks per task packet (task granularity)")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  command.add_option("--buffer-depth", options.params.bufferDepth, "task-manager local pool size, in packets")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  command.add_option("--static-fraction", options.params.staticFraction, "hybrid: share of tasks split statically")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
}

struct RunOutputOptions {
  std::string metricsFile;  // --metrics: the RunRecord as JSON
  std::string traceFile;    // --trace: the timeline as Chrome trace events
};

inline void addRunOutputOptions(CLI::App& command, RunOutputOptions& options) {
  command.add_option("--metrics", options.metricsFile, "write the run record (per-PE busy/idle, traffic, timeline) as JSON");
  command.add_option("--trace", options.traceFile, "write the task timeline in Chrome trace format (Perfetto, chrome://tracing)");
}

// Writes the files asked for; throws pr::InputError when one cannot be written.
inline void writeRunOutputs(const RunRecord& record, const RunOutputOptions& options) {
  if (!options.metricsFile.empty()) writeRunRecord(record, options.metricsFile);
  if (!options.traceFile.empty()) writeChromeTrace(record, options.traceFile);
}

}  // namespace pr::par
