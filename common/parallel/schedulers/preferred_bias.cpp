// Preferred-bias (conceptual) task allocation (seed 3.4.5): the tasks are divided into equal
// contiguous conceptual regions, one per PE, as in the balanced data-driven model, but handed
// out on demand. A PE takes from the front of its own region; once that is empty it helps the
// region with the most estimated work left, taking from its back so the owner keeps coherence.
#include <algorithm>
#include <mutex>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {
namespace {

class PreferredBiasScheduler : public Scheduler {
 public:
  std::string_view name() const override { return "preferred-bias"; }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) override {
    grain_ = std::max(1, params.grain);
    costs_.resize(tasks.size());
    for (std::size_t i = 0; i < tasks.size(); ++i) costs_[i] = tasks.tasks[i].costEstimate;
    regions_.clear();
    const auto portions = balancedSplit(tasks.size(), pes);
    for (const auto& portion : portions) {
      Region region;
      region.front = portion.empty() ? 0 : portion.front();
      region.back = region.front + static_cast<TaskId>(portion.size());
      for (TaskId id : portion) region.costLeft += costs_[id];
      regions_.push_back(region);
    }
  }

  // One lock around the controller's bookkeeping: choosing the region to help needs a
  // consistent view of all of them.
  void next(int pe, double, Grab& out) override {
    out.clear();
    std::lock_guard lock(mutex_);
    Region& own = regions_[pe];
    if (own.front < own.back) {
      const TaskId end = std::min<TaskId>(own.back, own.front + grain_);
      for (TaskId id = own.front; id < end; ++id) take(own, id, out);
      own.front = end;
    } else {
      int helped = -1;
      for (int r = 0; r < static_cast<int>(regions_.size()); ++r) {
        if (regions_[r].front < regions_[r].back &&
            (helped < 0 || regions_[r].costLeft > regions_[helped].costLeft))
          helped = r;
      }
      if (helped < 0) return;
      Region& other = regions_[helped];
      const TaskId start = std::max<TaskId>(other.front, other.back - grain_);
      for (TaskId id = start; id < other.back; ++id) take(other, id, out);
      other.back = start;
    }
    out.requests = 1;
    out.packets = 1;
    out.moved = out.tasks.size();
  }

 private:
  struct Region {
    TaskId front = 0, back = 0;  // tasks [front, back) not yet handed out
    double costLeft = 0.0;
  };

  void take(Region& region, TaskId id, Grab& out) {
    out.tasks.push_back(id);
    region.costLeft -= costs_[id];
  }

  std::size_t grain_ = 1;
  std::vector<double> costs_;
  std::vector<Region> regions_;
  std::mutex mutex_;
};

}  // namespace

std::unique_ptr<Scheduler> makePreferredBias() { return std::make_unique<PreferredBiasScheduler>(); }

}  // namespace pr::par
