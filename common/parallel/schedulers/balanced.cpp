// Balanced data-driven model (seed 3.2.1, figure 3.6): an equal number of tasks per PE, as
// contiguous portions fixed before the run; best when every task costs the same.
#include <numeric>

#include "common/parallel/schedulers/static_portions.h"
#include "common/util/error.h"

namespace pr::par {

std::vector<std::vector<TaskId>> balancedSplit(std::size_t n, int pes) {
  PR_CHECK(pes >= 1, "balancedSplit needs at least one PE");
  std::vector<std::vector<TaskId>> portions(pes);
  const std::size_t base = n / pes, extra = n % pes;
  TaskId next = 0;
  for (int p = 0; p < pes; ++p) {
    const std::size_t count = base + (static_cast<std::size_t>(p) < extra ? 1 : 0);
    portions[p].resize(count);
    std::iota(portions[p].begin(), portions[p].end(), next);
    next += static_cast<TaskId>(count);
  }
  return portions;
}

std::unique_ptr<Scheduler> makeBalancedDataDriven() {
  return std::make_unique<StaticPortionScheduler>(
      "balanced", [](const TaskSet& tasks, int pes) { return balancedSplit(tasks.size(), pes); });
}

}  // namespace pr::par
