// The schedule registry: one line per strategy (name -> factory -> description, and whether
// it needs cost estimates). Feeds --schedule validation and --help (run_options.h), run
// records, reports, and callers that decide whether to run a cost pre-pass.
#include <string>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {

// Factories, each defined in its strategy's file.
std::unique_ptr<Scheduler> makeBalancedDataDriven();
std::unique_ptr<Scheduler> makeUnbalancedDataDriven();
std::unique_ptr<Scheduler> makeDemandSerial();
std::unique_ptr<Scheduler> makeDemandSpiral();
std::unique_ptr<Scheduler> makeDemandRandom();
std::unique_ptr<Scheduler> makeDemandHotSpots();
std::unique_ptr<Scheduler> makeHybrid();
std::unique_ptr<Scheduler> makeTaskManager();
std::unique_ptr<Scheduler> makeDistributed();
std::unique_ptr<Scheduler> makePreferredBias();

namespace {
constexpr ScheduleProperties kNeedsCosts{true};
}  // namespace

const ScheduleRegistry& schedules() {
  static const ScheduleRegistry kSchedules(
      "schedule",
      {
          {"balanced", "balanced data-driven: equal contiguous portions, fixed before the run", makeBalancedDataDriven},
          {"unbalanced", "unbalanced data-driven: portions of equal estimated cost (pre-pass or profile)", makeUnbalancedDataDriven, kNeedsCosts},
          {"demand", "demand-driven task pool, serial (image) order", makeDemandSerial},
          {"spiral", "demand-driven task pool, spiral order from the image centre", makeDemandSpiral},
          {"random", "demand-driven task pool, random order", makeDemandRandom},
          {"hot-spots", "demand-driven task pool, most expensive (estimated) tasks first", makeDemandHotSpots, kNeedsCosts},
          {"hybrid", "hybrid: a static balanced first portion (--static-fraction), then on demand", makeHybrid},
          {"task-manager", "demand-driven with a per-PE local pool refilled ahead of need (--buffer-depth)", makeTaskManager},
          {"distributed", "distributed task management: an idle PE takes half a neighbour's pool", makeDistributed},
          {"preferred-bias", "conceptual regions per PE; a finished PE helps the region with most work left", makePreferredBias},
      });
  return kSchedules;
}

bool isSchedule(std::string_view name) { return schedules().contains(name); }

std::unique_ptr<Scheduler> makeScheduler(std::string_view name) { return schedules().find(name).make(); }

bool scheduleNeedsCostEstimates(std::string_view name) {
  return schedules().find(name).properties.needsCostEstimates;
}

std::string describeSchedules() { return schedules().describe(); }

}  // namespace pr::par
