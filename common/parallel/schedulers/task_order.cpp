// Task orders for the demand-driven supplier (seed 3.2.2): serial, spiral, random, hot-spots.
// Computed once per stage in Scheduler::reset, never per request.
#include "common/parallel/schedulers/task_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace pr::par {
namespace {

// splitmix64 (Steele et al. 2014): a fixed, portable stream, unlike std::shuffle's
// implementation-defined use of its engine.
std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace

std::string_view toString(TaskOrder order) {
  switch (order) {
    case TaskOrder::Serial: return "serial";
    case TaskOrder::Spiral: return "spiral";
    case TaskOrder::Random: return "random";
    case TaskOrder::HotSpots: return "hot-spots";
  }
  return "?";
}

std::vector<TaskId> taskOrder(const TaskSet& set, TaskOrder order, std::uint64_t seed) {
  const std::size_t n = set.size();
  std::vector<TaskId> ids(n);
  std::iota(ids.begin(), ids.end(), TaskId{0});
  switch (order) {
    case TaskOrder::Serial:
      break;
    case TaskOrder::Spiral: {
      if (n == 0) break;
      float minX = set.tasks[0].x, maxX = minX, minY = set.tasks[0].y, maxY = minY;
      for (const TaskInfo& t : set.tasks) {
        minX = std::min(minX, t.x), maxX = std::max(maxX, t.x);
        minY = std::min(minY, t.y), maxY = std::max(maxY, t.y);
      }
      const double cx = 0.5 * (double(minX) + maxX), cy = 0.5 * (double(minY) + maxY);
      struct Key { double ring, angle; };
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
      break;
    }
    case TaskOrder::Random: {
      std::uint64_t state = seed;
      for (std::size_t i = n; i > 1; --i) {
        const std::size_t j = splitmix64(state) % i;
        std::swap(ids[i - 1], ids[j]);
      }
      break;
    }
    case TaskOrder::HotSpots:
      std::stable_sort(ids.begin(), ids.end(), [&](TaskId a, TaskId b) {
        return set.tasks[a].costEstimate > set.tasks[b].costEstimate;
      });
      break;
  }
  return ids;
}

}  // namespace pr::par
