// Distributed task management (seed 3.4.4): the tasks start spread over the PEs' task pools
// (balanced contiguous portions); a PE whose pool is empty asks its neighbours, nearest first
// around a ring (p+1, p-1, p+2, ...), and takes half of the first non-empty pool it finds
// instead of going to the controller. Work stealing in today's words.
#include <algorithm>
#include <deque>
#include <mutex>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {
namespace {

class DistributedScheduler : public Scheduler {
 public:
  std::string_view name() const override { return "distributed"; }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) override {
    pes_ = pes;
    grain_ = std::max(1, params.grain);
    pools_.clear();
    for (int p = 0; p < pes_; ++p) pools_.push_back(std::make_unique<Pool>());
    const auto portions = balancedSplit(tasks.size(), pes_);
    for (int p = 0; p < pes_; ++p) pools_[p]->tasks.assign(portions[p].begin(), portions[p].end());
    initial_.assign(pes_, 0);
  }

  // Locks at most one pool at a time, so thieves cannot deadlock. A task is always in exactly
  // one pool or in the hands of exactly one PE, so it is handed out exactly once.
  void next(int pe, double, Grab& out) override {
    out.clear();
    if (!initial_[pe]) {  // the initial distribution counts as one packet from the controller
      initial_[pe] = 1;
      std::lock_guard lock(pools_[pe]->mutex);
      if (!pools_[pe]->tasks.empty()) {
        out.packets = 1;
        out.moved = pools_[pe]->tasks.size();
      }
    }
    for (;;) {
      if (takeOwn(pe, out)) return;
      std::vector<TaskId> stolen;
      int victim = -1;
      for (int d = 1; d < pes_ && victim < 0; ++d) {
        for (int q : {(pe + d) % pes_, ((pe - d) % pes_ + pes_) % pes_}) {
          Pool& pool = *pools_[q];
          std::lock_guard lock(pool.mutex);
          if (pool.tasks.empty()) continue;
          const std::size_t half = (pool.tasks.size() + 1) / 2;
          stolen.assign(pool.tasks.end() - half, pool.tasks.end());
          pool.tasks.erase(pool.tasks.end() - half, pool.tasks.end());
          victim = q;
          break;
        }
      }
      if (victim < 0) return;  // every pool is empty: the stage's tasks are all handed out
      {
        std::lock_guard lock(pools_[pe]->mutex);
        pools_[pe]->tasks.insert(pools_[pe]->tasks.end(), stolen.begin(), stolen.end());
      }
      out.from = victim;
      out.requests += 1;
      out.packets += 1;
      out.moved += stolen.size();
      // Another thief may empty our pool between the insert and takeOwn: then search again.
    }
  }

 private:
  struct Pool {
    std::mutex mutex;
    std::deque<TaskId> tasks;
  };

  bool takeOwn(int pe, Grab& out) {
    Pool& pool = *pools_[pe];
    std::lock_guard lock(pool.mutex);
    if (pool.tasks.empty()) return false;
    const std::size_t run = std::min(grain_, pool.tasks.size());
    out.tasks.assign(pool.tasks.begin(), pool.tasks.begin() + run);
    pool.tasks.erase(pool.tasks.begin(), pool.tasks.begin() + run);
    return true;
  }

  int pes_ = 1;
  std::size_t grain_ = 1;
  std::vector<std::unique_ptr<Pool>> pools_;
  std::vector<char> initial_;
};

}  // namespace

std::unique_ptr<Scheduler> makeDistributed() { return std::make_unique<DistributedScheduler>(); }

}  // namespace pr::par
