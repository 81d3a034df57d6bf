// Tasks: one application of the algorithm to one principal data item (PDI) — a tile, a
// primitive batch, a ray batch. A renderer describes one stage's tasks as a TaskSet (ids
// 0..N-1 in image order, with cost estimates and positions); a Scheduler decides which PE runs
// which id, and the Runtime calls the renderer's work function with it (seed, chapter 3).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pr::par {

// Index of a task in its TaskSet; ids follow image (serial) order.
using TaskId = std::int64_t;

struct TaskInfo {
  // Relative cost of the task, from a cheap pre-pass or a profile of an earlier run. The
  // unbalanced data-driven split and the hot-spots-first order read it; the simulator reads it
  // as seconds. 1 for every task when nothing is known.
  double costEstimate = 1.0;
  // Position of the PDI in the problem domain (tile centre in tiles or pixels); spiral order
  // starts from the centre of the bounding box of these positions.
  float x = 0.0f, y = 0.0f;
  // The PE that holds the data the task needs (a data-partitioned renderer's owner of what the
  // tile's camera rays reach), or -1 when unknown. Preferred-bias makes each PE's conceptual
  // region of the tasks that prefer it; the other strategies ignore it.
  int preferredPe = -1;
};

struct TaskSet {
  std::vector<TaskInfo> tasks;

  std::size_t size() const { return tasks.size(); }
  bool empty() const { return tasks.empty(); }

  // n tasks of equal cost, in a row.
  static TaskSet uniform(std::size_t n, double cost = 1.0) {
    TaskSet set;
    set.tasks.resize(n);
    for (std::size_t i = 0; i < n; ++i) set.tasks[i] = {cost, static_cast<float>(i), 0.0f};
    return set;
  }
  // One task per cost, in a row (x = index).
  static TaskSet fromCosts(const std::vector<double>& costs) {
    TaskSet set;
    set.tasks.resize(costs.size());
    for (std::size_t i = 0; i < costs.size(); ++i) set.tasks[i] = {costs[i], static_cast<float>(i), 0.0f};
    return set;
  }
  // cols x rows tiles in row-major image order, positions at the tile centres.
  static TaskSet grid(int cols, int rows, double cost = 1.0) {
    TaskSet set;
    set.tasks.reserve(static_cast<std::size_t>(cols) * rows);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) set.tasks.push_back({cost, c + 0.5f, r + 0.5f});
    return set;
  }
};

}  // namespace pr::par
