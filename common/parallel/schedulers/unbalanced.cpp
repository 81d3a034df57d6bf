// Unbalanced data-driven model (seed 3.2.1, figure 3.8): portions of equal estimated cost,
// from a cheap pre-pass or a profile recorded by an earlier run (taskCostProfile), fixed
// before the run. The estimates are TaskInfo::costEstimate.
#include <algorithm>
#include <numeric>

#include "common/parallel/schedulers/static_portions.h"
#include "common/util/error.h"

namespace pr::par {

std::vector<std::vector<TaskId>> unbalancedSplit(const TaskSet& tasks, int pes) {
  PR_CHECK(pes >= 1, "unbalancedSplit needs at least one PE");
  // Longest processing time first (Graham 1969): sorting by decreasing cost is the seed's
  // "preprocessing step"; each task then goes to the PE with the least estimated work so far,
  // so no PE exceeds total/P by more than one task's cost.
  std::vector<TaskId> byCost(tasks.size());
  std::iota(byCost.begin(), byCost.end(), TaskId{0});
  std::stable_sort(byCost.begin(), byCost.end(), [&](TaskId a, TaskId b) {
    return tasks.tasks[a].costEstimate > tasks.tasks[b].costEstimate;
  });
  std::vector<std::vector<TaskId>> portions(pes);
  std::vector<double> load(pes, 0.0);
  for (TaskId id : byCost) {
    const int p = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    portions[p].push_back(id);
    load[p] += tasks.tasks[id].costEstimate;
  }
  // Image order within a portion keeps neighbouring PDIs together (data coherence).
  for (auto& portion : portions) std::sort(portion.begin(), portion.end());
  return portions;
}

std::unique_ptr<Scheduler> makeUnbalancedDataDriven() {
  return std::make_unique<StaticPortionScheduler>("unbalanced", unbalancedSplit);
}

}  // namespace pr::par
