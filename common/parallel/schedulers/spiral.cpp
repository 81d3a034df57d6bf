// Demand-driven model with spiral allocation (seed 3.2.2, figure 3.11): tasks from the image
// centre outwards, where the subject (and the expensive pixels) usually are.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/parallel/schedulers/demand_pool.h"

namespace pr::par {

std::vector<TaskId> spiralOrder(const TaskSet& set, const ScheduleParams&) {
  const std::size_t n = set.size();
  std::vector<TaskId> ids(n);
  std::iota(ids.begin(), ids.end(), TaskId{0});
  if (n == 0) return ids;
  float minX = set.tasks[0].x, maxX = minX, minY = set.tasks[0].y, maxY = minY;
  for (const TaskInfo& t : set.tasks) {
    minX = std::min(minX, t.x), maxX = std::max(maxX, t.x);
    minY = std::min(minY, t.y), maxY = std::max(maxY, t.y);
  }
  const double cx = 0.5 * (double(minX) + maxX), cy = 0.5 * (double(minY) + maxY);
  struct Key {
    double ring, angle;
  };
  std::vector<Key> keys(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = set.tasks[i].x - cx, dy = set.tasks[i].y - cy;
    double angle = std::atan2(dy, dx);
    if (angle < 0) angle += 2.0 * M_PI;
    // Square rings (Chebyshev distance) walk the tiles as figure 3.11 does.
    keys[i] = {std::max(std::abs(dx), std::abs(dy)), angle};
  }
  std::stable_sort(ids.begin(), ids.end(), [&](TaskId a, TaskId b) {
    if (keys[a].ring != keys[b].ring) return keys[a].ring < keys[b].ring;
    return keys[a].angle < keys[b].angle;
  });
  return ids;
}

std::unique_ptr<Scheduler> makeDemandSpiral() { return std::make_unique<DemandPoolScheduler>("spiral", spiralOrder); }

}  // namespace pr::par
