// Task manager with a local task pool (seed 3.4.3): each PE keeps up to bufferDepth task
// packets of grain tasks locally, refilled from the controller's pool (image order) as soon as
// it runs one, so the next request is normally satisfied at once. Only an empty local pool
// makes the PE wait for a packet. Tasks buffered at a busy PE cannot be taken by an idle one:
// deeper buffers trade request latency for the end-of-stage imbalance the seed warns about.
// Across ranks the local pools are where their PEs are and the controller's pool on rank 0: a
// PE on another rank asks for its refills by message and works on while they travel
// (Scheduler::localPoolsAcrossRanks).
#include <algorithm>
#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <utility>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {
namespace {

class TaskManagerScheduler : public Scheduler {
 public:
  std::string_view name() const override { return "task-manager"; }

  bool localPoolsAcrossRanks() const override { return true; }
  // Rank 0's PEs take packets from the controller's pool in place; another rank's ask for them.
  void setLocalPes(int first, int) override { remote_ = first != 0; }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) override {
    total_ = tasks.size();
    grain_ = std::max(1, params.grain);
    capacity_ = grain_ * std::max(1, params.bufferDepth);
    local_.clear();
    for (int p = 0; p < pes; ++p) local_.push_back(std::make_unique<LocalPool>());
    cursor_.store(0, std::memory_order_relaxed);
  }

  // A local pool is its PE's (and, across ranks, the thread that hands it a refill's); the
  // controller's pool is an atomic cursor.
  void next(int pe, double, Grab& out) override {
    out.clear();
    LocalPool& pool = *local_[pe];
    std::lock_guard lock(pool.mutex);
    out.blocking = pool.tasks.empty();
    if (remote_) return nextAsking(pool, out);
    if (pool.tasks.empty() && !fetchPacket(pool.tasks, out)) return;
    take(pool, out);
    // Refill ahead of need while the application process works on the tasks just handed out.
    while (pool.tasks.size() + grain_ <= capacity_ && fetchPacket(pool.tasks, out)) {
    }
  }

  std::vector<TaskId> supplyPacket(int) override {
    std::vector<TaskId> packet;
    const auto [start, end] = claimPacket();
    for (std::size_t id = start; id < end; ++id) packet.push_back(static_cast<TaskId>(id));
    return packet;
  }

  void refill(int pe, std::vector<TaskId> tasks) override {
    LocalPool& pool = *local_[pe];
    std::lock_guard lock(pool.mutex);
    --pool.inFlight;
    if (tasks.empty()) pool.exhausted = true;
    pool.tasks.insert(pool.tasks.end(), tasks.begin(), tasks.end());
  }

 private:
  struct LocalPool {
    std::mutex mutex;
    std::deque<TaskId> tasks;
    std::size_t inFlight = 0;  // refills asked for and not yet arrived (another rank's PE)
    bool exhausted = false;    // a refill came back empty: the controller's pool is spent
  };

  // On another rank than the controller's: the refills are asked for, and arrive later.
  void nextAsking(LocalPool& pool, Grab& out) {
    if (pool.tasks.empty()) {
      if (pool.exhausted && pool.inFlight == 0) return;  // no task left for this PE
      if (pool.inFlight == 0) askRefill(pool, out);
      out.askPe = Grab::kAwaitRefill;
      return;
    }
    take(pool, out);
    while (!pool.exhausted && pool.tasks.size() + (pool.inFlight + 1) * grain_ <= capacity_) askRefill(pool, out);
  }

  void askRefill(LocalPool& pool, Grab& out) {
    ++pool.inFlight;
    ++out.refillRequests;
  }

  void take(LocalPool& pool, Grab& out) {
    const std::size_t run = std::min(grain_, pool.tasks.size());
    out.tasks.assign(pool.tasks.begin(), pool.tasks.begin() + run);
    pool.tasks.erase(pool.tasks.begin(), pool.tasks.begin() + run);
    out.from = kController;
  }

  // The next packet of the controller's pool: task ids [first, second), empty once it is spent.
  std::pair<std::size_t, std::size_t> claimPacket() {
    const std::size_t start = std::min(total_, cursor_.fetch_add(grain_, std::memory_order_relaxed));
    return {start, std::min(total_, start + grain_)};
  }

  bool fetchPacket(std::deque<TaskId>& pool, Grab& out) {
    const auto [start, end] = claimPacket();
    if (start == end) return false;
    for (std::size_t id = start; id < end; ++id) pool.push_back(static_cast<TaskId>(id));
    out.requests += 1;
    out.packets += 1;
    out.moved += end - start;
    return true;
  }

  std::size_t total_ = 0, grain_ = 1, capacity_ = 2;
  bool remote_ = false;
  std::vector<std::unique_ptr<LocalPool>> local_;
  std::atomic<std::size_t> cursor_{0};
};

}  // namespace

std::unique_ptr<Scheduler> makeTaskManager() { return std::make_unique<TaskManagerScheduler>(); }

}  // namespace pr::par
