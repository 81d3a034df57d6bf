// Distributed task management (seed 3.4.4): the tasks start spread over the PEs' task pools
// (balanced contiguous portions); a PE whose pool is empty asks its neighbours, nearest first
// around a ring (p+1, p-1, p+2, ...), and takes half of the first non-empty pool it finds
// instead of going to the controller. Work stealing in today's words. Across ranks each rank
// keeps its own PEs' pools; a search that reaches a PE on another rank asks it by message
// (Scheduler::localPoolsAcrossRanks), in the same ring order, and does not ask a pool that
// answered empty again in the stage. Every pool asked is a request and an answer, an empty one
// too (Grab::emptyAnswers): in one process as across ranks, and in the simulator.
#include <algorithm>
#include <deque>
#include <mutex>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {
namespace {

class DistributedScheduler : public Scheduler {
 public:
  std::string_view name() const override { return "distributed"; }

  bool localPoolsAcrossRanks() const override { return true; }
  void setLocalPes(int first, int count) override {
    firstLocal_ = first;
    localCount_ = count;
  }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) override {
    pes_ = pes;
    answeredEmpty_.assign(std::size_t(pes), {});
    askedEmpty_.assign(std::size_t(pes), std::vector<char>(std::size_t(pes), 0));
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
      // Each other PE once: at distance d = P / 2 (P even) the two ways round meet at one PE.
      for (int d = 1; d <= pes_ / 2 && victim < 0; ++d) {
        const int after = (pe + d) % pes_, before = ((pe - d) % pes_ + pes_) % pes_;
        for (int way = 0; way < (after == before ? 1 : 2); ++way) {
          const int q = way == 0 ? after : before;
          if (!local(q)) {  // its pool is on another rank: ask it, unless it answered empty
            std::vector<char>& empty = answeredEmpty_[std::size_t(pe)];
            if (!empty.empty() && empty[std::size_t(q)]) continue;
            out.askPe = q;
            return;
          }
          std::vector<char>& askedEmpty = askedEmpty_[std::size_t(pe)];
          if (askedEmpty[std::size_t(q)]) continue;  // asked before another rank's answer
          stolen = stealFrom(q);
          if (stolen.empty()) {  // asked, and answered with an empty packet
            askedEmpty[std::size_t(q)] = 1;
            out.requests += 1;
            out.packets += 1;
            out.emptyAnswers += 1;
            continue;
          }
          victim = q;
          break;
        }
      }
      endSearch(pe);
      if (victim < 0) return;  // every pool is empty: the stage's tasks are all handed out
      addToPool(pe, stolen);
      out.from = victim;
      out.requests += 1;
      out.packets += 1;
      out.moved += stolen.size();
      // Another thief may empty our pool between the insert and takeOwn: then search again.
    }
  }

  // Half of victim's pool (rounded up), from its far end; none when it is empty.
  std::vector<TaskId> stealFrom(int victim) override {
    Pool& pool = *pools_[victim];
    std::lock_guard lock(pool.mutex);
    const std::size_t half = (pool.tasks.size() + 1) / 2;
    std::vector<TaskId> stolen(pool.tasks.end() - half, pool.tasks.end());
    pool.tasks.erase(pool.tasks.end() - half, pool.tasks.end());
    return stolen;
  }

  void stolen(int pe, int victim, std::vector<TaskId> tasks) override {
    if (tasks.empty()) {
      std::vector<char>& empty = answeredEmpty_[std::size_t(pe)];
      if (empty.empty()) empty.assign(std::size_t(pes_), 0);
      empty[std::size_t(victim)] = 1;
      return;
    }
    endSearch(pe);
    addToPool(pe, tasks);
  }

 private:
  struct Pool {
    std::mutex mutex;
    std::deque<TaskId> tasks;
  };

  void addToPool(int pe, const std::vector<TaskId>& tasks) {
    std::lock_guard lock(pools_[pe]->mutex);
    pools_[pe]->tasks.insert(pools_[pe]->tasks.end(), tasks.begin(), tasks.end());
  }

  // A search is over (a steal, or every pool empty): the next one asks every pool again.
  void endSearch(int pe) { std::fill(askedEmpty_[std::size_t(pe)].begin(), askedEmpty_[std::size_t(pe)].end(), 0); }

  bool local(int q) const { return localCount_ < 0 || (q >= firstLocal_ && q < firstLocal_ + localCount_); }

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
  int firstLocal_ = 0, localCount_ = -1;  // -1: every PE is local
  // Per PE (by its own thread only): the PEs on other ranks whose pools answered it empty.
  std::vector<std::vector<char>> answeredEmpty_;
  // Per PE (by its own thread only): the pools on its rank that answered empty in the current
  // search, which an answer from another rank interrupts; so that the search goes on where it
  // was, asking each pool once, as in one process.
  std::vector<std::vector<char>> askedEmpty_;
};

}  // namespace

std::unique_ptr<Scheduler> makeDistributed() { return std::make_unique<DistributedScheduler>(); }

}  // namespace pr::par
