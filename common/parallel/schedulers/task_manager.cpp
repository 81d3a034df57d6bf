// Task manager with a local task pool (seed 3.4.3): each PE keeps up to bufferDepth task
// packets of grain tasks locally, refilled from the controller's pool (image order) as soon as
// it runs one, so the next request is normally satisfied at once. Only an empty local pool
// makes the PE wait for a packet. Tasks buffered at a busy PE cannot be taken by an idle one:
// deeper buffers trade request latency for the end-of-stage imbalance the seed warns about.
#include <algorithm>
#include <atomic>
#include <deque>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {
namespace {

class TaskManagerScheduler : public Scheduler {
 public:
  std::string_view name() const override { return "task-manager"; }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) override {
    total_ = tasks.size();
    grain_ = std::max(1, params.grain);
    capacity_ = grain_ * std::max(1, params.bufferDepth);
    local_.assign(pes, {});
    cursor_.store(0, std::memory_order_relaxed);
  }

  // Local pools are private to their PE; the controller's pool is an atomic cursor.
  void next(int pe, double, Grab& out) override {
    out.clear();
    std::deque<TaskId>& pool = local_[pe];
    out.blocking = pool.empty();
    if (pool.empty() && !fetchPacket(pool, out)) return;
    const std::size_t run = std::min(grain_, pool.size());
    out.tasks.assign(pool.begin(), pool.begin() + run);
    pool.erase(pool.begin(), pool.begin() + run);
    // Refill ahead of need while the application process works on the tasks just handed out.
    while (pool.size() + grain_ <= capacity_ && fetchPacket(pool, out)) {
    }
    out.from = kController;
  }

 private:
  bool fetchPacket(std::deque<TaskId>& pool, Grab& out) {
    const std::size_t start = cursor_.fetch_add(grain_, std::memory_order_relaxed);
    if (start >= total_) return false;
    const std::size_t end = std::min(total_, start + grain_);
    for (std::size_t id = start; id < end; ++id) pool.push_back(static_cast<TaskId>(id));
    out.requests += 1;
    out.packets += 1;
    out.moved += end - start;
    return true;
  }

  std::size_t total_ = 0, grain_ = 1, capacity_ = 2;
  std::vector<std::deque<TaskId>> local_;
  std::atomic<std::size_t> cursor_{0};
};

}  // namespace

std::unique_ptr<Scheduler> makeTaskManager() { return std::make_unique<TaskManagerScheduler>(); }

}  // namespace pr::par
