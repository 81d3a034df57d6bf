// Data-driven computational models (seed 3.2.1): every task is allocated to a PE before
// computation starts and sent as one task packet per PE. Balanced: equal contiguous portions.
// Unbalanced: portions of equal estimated cost, from a pre-pass or a recorded profile.
#include <algorithm>
#include <numeric>

#include "common/parallel/schedulers/scheduler.h"
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

namespace {

// Hands each PE its whole precomputed portion on its first request, as one task packet.
class DataDrivenScheduler : public Scheduler {
 public:
  explicit DataDrivenScheduler(bool byCost) : byCost_(byCost) {}
  std::string_view name() const override { return byCost_ ? "unbalanced" : "balanced"; }

  void reset(const TaskSet& tasks, const ScheduleParams& params) override {
    portions_ = byCost_ ? unbalancedSplit(tasks, params.pes) : balancedSplit(tasks.size(), params.pes);
    sent_.assign(params.pes, 0);
  }

  // Each PE touches only its own portion and flag: no synchronisation needed.
  void next(int pe, double, Grab& out) override {
    out.clear();
    if (sent_[pe] || portions_[pe].empty()) return;
    sent_[pe] = 1;
    out.tasks = portions_[pe];
    out.packets = 1;
    out.moved = out.tasks.size();
  }

 private:
  bool byCost_;
  std::vector<std::vector<TaskId>> portions_;
  std::vector<char> sent_;
};

}  // namespace

std::unique_ptr<Scheduler> makeBalancedDataDriven() { return std::make_unique<DataDrivenScheduler>(false); }
std::unique_ptr<Scheduler> makeUnbalancedDataDriven() { return std::make_unique<DataDrivenScheduler>(true); }

}  // namespace pr::par
