// DemandPoolScheduler: the demand-driven model's task supplier (seed 3.2.2) — a central task
// pool at the system controller; an idle PE demands the next task packet (grain tasks). The
// strategies differ only in the order of the pool, computed once per stage: serial
// (demand_driven.cpp), spiral (spiral.cpp), random (random.cpp), hot-spots first
// (hot_spots.cpp). The supplier is one atomic cursor into that order: a request costs one
// fetch_add, so PEs never wait on each other for a task.
#pragma once

#include <algorithm>
#include <atomic>
#include <string_view>
#include <vector>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {

// A permutation of [0, tasks.size()): the order in which the pool hands tasks out.
using PoolOrder = std::vector<TaskId> (*)(const TaskSet& tasks, const ScheduleParams& params);

// The orders, one per strategy file.
// Image order.
std::vector<TaskId> serialOrder(const TaskSet& tasks, const ScheduleParams& params);
// Square rings around the centre of the positions' bounding box, inner rings first; within a
// ring by angle counter-clockwise from +x; ties by id (figure 3.11).
std::vector<TaskId> spiralOrder(const TaskSet& tasks, const ScheduleParams& params);
// Fisher-Yates driven by splitmix64(params.seed), identical on every platform.
std::vector<TaskId> randomOrder(const TaskSet& tasks, const ScheduleParams& params);
// Decreasing cost estimate, ties in image order.
std::vector<TaskId> hotSpotsOrder(const TaskSet& tasks, const ScheduleParams& params);

class DemandPoolScheduler : public Scheduler {
 public:
  DemandPoolScheduler(std::string_view name, PoolOrder order) : name_(name), order_(order) {}
  std::string_view name() const override { return name_; }

  void reset(const TaskSet& tasks, int /*pes: one pool for all*/, const ScheduleParams& params) override {
    pool_ = order_(tasks, params);
    grain_ = static_cast<std::size_t>(std::max(1, params.grain));
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
  PoolOrder order_;
  std::vector<TaskId> pool_;
  std::size_t grain_ = 1;
  std::atomic<std::size_t> cursor_{0};
};

}  // namespace pr::par
