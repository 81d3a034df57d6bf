// Demand-driven computational model (seed 3.2.2): a central task pool at the system
// controller; an idle PE demands the next task packet (grain tasks). The pool order is serial,
// spiral, random or hot-spots first. The supplier is one atomic cursor into the precomputed
// order: a request costs one fetch_add, so PEs never wait on each other for a task.
#include <algorithm>
#include <atomic>

#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/schedulers/task_order.h"

namespace pr::par {
namespace {

class DemandDrivenScheduler : public Scheduler {
 public:
  DemandDrivenScheduler(std::string_view name, TaskOrder order) : name_(name), order_(order) {}
  std::string_view name() const override { return name_; }

  void reset(const TaskSet& tasks, const ScheduleParams& params) override {
    pool_ = taskOrder(tasks, order_, params.seed);
    grain_ = std::max(1, params.grain);
    cursor_.store(0, std::memory_order_relaxed);
  }

  void next(int, double, Grab& out) override {
    out.clear();
    const std::size_t start = cursor_.fetch_add(grain_, std::memory_order_relaxed);
    if (start >= pool_.size()) return;
    const std::size_t end = std::min(pool_.size(), start + grain_);
    out.tasks.assign(pool_.begin() + start, pool_.begin() + end);
    out.requests = 1;
    out.packets = 1;
    out.moved = end - start;
  }

 private:
  std::string_view name_;
  TaskOrder order_;
  std::vector<TaskId> pool_;
  std::size_t grain_ = 1;
  std::atomic<std::size_t> cursor_{0};
};

}  // namespace

std::unique_ptr<Scheduler> makeDemandSerial() { return std::make_unique<DemandDrivenScheduler>("demand", TaskOrder::Serial); }
std::unique_ptr<Scheduler> makeDemandSpiral() { return std::make_unique<DemandDrivenScheduler>("spiral", TaskOrder::Spiral); }
std::unique_ptr<Scheduler> makeDemandRandom() { return std::make_unique<DemandDrivenScheduler>("random", TaskOrder::Random); }
std::unique_ptr<Scheduler> makeDemandHotSpots() {
  return std::make_unique<DemandDrivenScheduler>("hot-spots", TaskOrder::HotSpots);
}

}  // namespace pr::par
