// The schedule registry: one line per strategy (name -> factory -> description). Feeds
// --schedule validation and --help (schedule_options.h), run records and reports.
#include <string>

#include "common/parallel/schedulers/scheduler.h"
#include "common/util/error.h"

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

const std::vector<ScheduleInfo>& schedules() {
  static const std::vector<ScheduleInfo> kSchedules = {
      {"balanced", "balanced data-driven: equal contiguous portions, fixed before the run", makeBalancedDataDriven},
      {"unbalanced", "unbalanced data-driven: portions of equal estimated cost (pre-pass or profile)", makeUnbalancedDataDriven},
      {"demand", "demand-driven task pool, serial (image) order", makeDemandSerial},
      {"spiral", "demand-driven task pool, spiral order from the image centre", makeDemandSpiral},
      {"random", "demand-driven task pool, random order", makeDemandRandom},
      {"hot-spots", "demand-driven task pool, most expensive (estimated) tasks first", makeDemandHotSpots},
      {"hybrid", "hybrid: a static balanced first portion (--static-fraction), then on demand", makeHybrid},
      {"task-manager", "demand-driven with a per-PE local pool refilled ahead of need (--buffer-depth)", makeTaskManager},
      {"distributed", "distributed task management: an idle PE takes half a neighbour's pool", makeDistributed},
      {"preferred-bias", "conceptual regions per PE; a finished PE helps the region with most work left", makePreferredBias},
  };
  return kSchedules;
}

bool isSchedule(std::string_view name) {
  for (const ScheduleInfo& s : schedules())
    if (s.name == name) return true;
  return false;
}

std::unique_ptr<Scheduler> makeScheduler(std::string_view name) {
  std::string names;
  for (const ScheduleInfo& s : schedules()) {
    if (s.name == name) return s.make();
    names += names.empty() ? "" : ", ";
    names += s.name;
  }
  throw InputError("unknown schedule '" + std::string(name) + "' (expected one of: " + names + ")");
}

std::string describeSchedules() {
  std::string text;
  for (const ScheduleInfo& s : schedules()) {
    text += "  ";
    text += s.name;
    text += std::string(s.name.size() < 15 ? 15 - s.name.size() : 1, ' ');
    text += s.description;
    text += "\n";
  }
  return text;
}

}  // namespace pr::par
