// Preferred-bias (conceptual) task allocation (seed 3.4.5): the tasks are divided into conceptual
// regions, one per PE, handed out on demand. A task that names the PE holding its data
// (TaskInfo::preferredPe) is in that PE's region; the others are in the region of the PE whose
// equal contiguous portion holds them, as in the balanced data-driven model. A PE takes from
// the front of its own region; once that is empty it helps the region with the most estimated
// work left, taking from its back so the owner keeps coherence.
#include <algorithm>
#include <mutex>
#include <vector>

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
    regions_.assign(static_cast<std::size_t>(pes), Region{});
    // The portions are contiguous and ascending, so each region's ids come in id order.
    const auto portions = balancedSplit(tasks.size(), pes);
    for (int p = 0; p < pes; ++p)
      for (TaskId id : portions[p]) {
        const int preferred = tasks.tasks[id].preferredPe;
        Region& r = regions_[preferred >= 0 && preferred < pes ? preferred : p];
        r.ids.push_back(id);
        r.costLeft += costs_[id];
      }
    for (Region& r : regions_) r.back = r.ids.size();
  }

  // One lock around the controller's bookkeeping: choosing the region to help needs a
  // consistent view of all of them.
  void next(int pe, double, Grab& out) override {
    out.clear();
    std::lock_guard lock(mutex_);
    Region& own = regions_[pe];
    if (own.front < own.back) {
      const std::size_t end = std::min(own.back, own.front + grain_);
      for (std::size_t i = own.front; i < end; ++i) take(own, i, out);
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
      const std::size_t start = other.back - std::min(grain_, other.back - other.front);
      for (std::size_t i = start; i < other.back; ++i) take(other, i, out);
      other.back = start;
    }
    out.requests = 1;
    out.packets = 1;
    out.moved = out.tasks.size();
  }

 private:
  struct Region {
    std::vector<TaskId> ids;          // in id order
    std::size_t front = 0, back = 0;  // ids[front, back) not yet handed out
    double costLeft = 0.0;
  };

  void take(Region& region, std::size_t i, Grab& out) {
    out.tasks.push_back(region.ids[i]);
    region.costLeft -= costs_[region.ids[i]];
  }

  std::size_t grain_ = 1;
  std::vector<double> costs_;
  std::vector<Region> regions_;
  std::mutex mutex_;
};

}  // namespace

std::unique_ptr<Scheduler> makePreferredBias() { return std::make_unique<PreferredBiasScheduler>(); }

}  // namespace pr::par
