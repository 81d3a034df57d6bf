// Hybrid computational model (seed 3.2.3): a known first portion of the tasks is allocated
// data-driven (balanced contiguous portions, one packet per PE, no request traffic), the rest
// is supplied on demand in image order. ScheduleParams::staticFraction sets the first portion.
#include <algorithm>
#include <atomic>
#include <cmath>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {
namespace {

class HybridScheduler : public Scheduler {
 public:
  std::string_view name() const override { return "hybrid"; }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) override {
    const double fraction = std::clamp(params.staticFraction, 0.0, 1.0);
    staticCount_ = static_cast<std::size_t>(std::ceil(fraction * tasks.size()));
    portions_ = balancedSplit(staticCount_, pes);
    sent_.assign(pes, 0);
    total_ = tasks.size();
    grain_ = std::max(1, params.grain);
    cursor_.store(staticCount_, std::memory_order_relaxed);
  }

  void next(int pe, double, Grab& out) override {
    out.clear();
    if (!sent_[pe]) {  // only PE pe touches sent_[pe]
      sent_[pe] = 1;
      if (!portions_[pe].empty()) {
        out.tasks = portions_[pe];
        out.packets = 1;
        out.moved = out.tasks.size();
        return;
      }
    }
    const std::size_t start = cursor_.fetch_add(grain_, std::memory_order_relaxed);
    if (start >= total_) return;
    const std::size_t end = std::min(total_, start + grain_);
    for (std::size_t id = start; id < end; ++id) out.tasks.push_back(static_cast<TaskId>(id));
    out.requests = 1;
    out.packets = 1;
    out.moved = end - start;
  }

 private:
  std::size_t staticCount_ = 0, total_ = 0, grain_ = 1;
  std::vector<std::vector<TaskId>> portions_;
  std::vector<char> sent_;
  std::atomic<std::size_t> cursor_{0};
};

}  // namespace

std::unique_ptr<Scheduler> makeHybrid() { return std::make_unique<HybridScheduler>(); }

}  // namespace pr::par
