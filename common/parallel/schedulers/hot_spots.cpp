// Demand-driven model, hot spots first (seed 3.2.2): the tasks with the highest cost estimate
// are handed out first, so no PE starts an expensive task near the end of the stage.
#include <algorithm>
#include <numeric>

#include "common/parallel/schedulers/demand_pool.h"

namespace pr::par {

std::vector<TaskId> hotSpotsOrder(const TaskSet& tasks, const ScheduleParams&) {
  std::vector<TaskId> ids(tasks.size());
  std::iota(ids.begin(), ids.end(), TaskId{0});
  std::stable_sort(ids.begin(), ids.end(), [&](TaskId a, TaskId b) {
    return tasks.tasks[a].costEstimate > tasks.tasks[b].costEstimate;
  });
  return ids;
}

std::unique_ptr<Scheduler> makeDemandHotSpots() {
  return std::make_unique<DemandPoolScheduler>("hot-spots", hotSpotsOrder);
}

}  // namespace pr::par
