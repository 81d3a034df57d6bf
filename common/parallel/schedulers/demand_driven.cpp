// Demand-driven model with serial allocation (seed 3.2.2, figure 3.10): the pool hands tasks
// out in image order.
#include <numeric>

#include "common/parallel/schedulers/demand_pool.h"

namespace pr::par {

std::vector<TaskId> serialOrder(const TaskSet& tasks, const ScheduleParams&) {
  std::vector<TaskId> ids(tasks.size());
  std::iota(ids.begin(), ids.end(), TaskId{0});
  return ids;
}

std::unique_ptr<Scheduler> makeDemandSerial() { return std::make_unique<DemandPoolScheduler>("demand", serialOrder); }

}  // namespace pr::par
