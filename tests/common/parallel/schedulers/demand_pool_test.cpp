// The demand-driven pool's allocation orders: serial, spiral, random, hot-spots first.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>

#include "common/parallel/schedulers/demand_pool.h"

using namespace pr::par;

TEST_CASE("DemandPool: spiral starts with the four centre tiles of a 4x4 grid, then the ring") {
  const TaskSet grid = TaskSet::grid(4, 4);
  const auto order = spiralOrder(grid, {});
  REQUIRE(order.size() == 16);
  // Centre (2, 2); the inner ring is tiles (1,1) (2,1) (1,2) (2,2) = ids 5 6 9 10, by angle
  // from +x counter-clockwise (y down in image space): 10 (45deg), 9 (135), 5 (225), 6 (315).
  CHECK(std::vector<TaskId>(order.begin(), order.begin() + 4) == std::vector<TaskId>{10, 9, 5, 6});
  std::vector<TaskId> rest(order.begin() + 4, order.end());
  for (TaskId inner : {5, 6, 9, 10}) CHECK(std::find(rest.begin(), rest.end(), inner) == rest.end());
}

TEST_CASE("DemandPool: random order is a permutation, fixed by its seed") {
  const TaskSet set = TaskSet::uniform(1000);
  ScheduleParams seven, eight;
  seven.seed = 7;
  eight.seed = 8;
  const auto a = randomOrder(set, seven), b = randomOrder(set, seven), c = randomOrder(set, eight);
  CHECK(a == b);
  CHECK(a != c);
  auto sorted = a;
  std::sort(sorted.begin(), sorted.end());
  std::vector<TaskId> ids(1000);
  std::iota(ids.begin(), ids.end(), TaskId{0});
  CHECK(sorted == ids);
  CHECK(a != ids);
}

TEST_CASE("DemandPool: hot-spots by decreasing estimate, ties in image order, serial is identity") {
  const TaskSet set = TaskSet::fromCosts({1, 5, 2, 5, 3});
  CHECK(hotSpotsOrder(set, {}) == std::vector<TaskId>{1, 3, 4, 2, 0});
  CHECK(serialOrder(set, {}) == std::vector<TaskId>{0, 1, 2, 3, 4});
}

TEST_CASE("DemandPool: packets of grain tasks in pool order until the pool is empty") {
  DemandPoolScheduler pool("hot-spots", hotSpotsOrder);
  ScheduleParams params;
  params.grain = 2;
  pool.reset(TaskSet::fromCosts({1, 5, 2, 5, 3}), 2, params);
  Grab grab;
  pool.next(0, 0.0, grab);
  CHECK(grab.tasks == std::vector<TaskId>{1, 3});
  CHECK(grab.requests == 1);
  pool.next(1, 0.0, grab);
  CHECK(grab.tasks == std::vector<TaskId>{4, 2});
  pool.next(0, 0.0, grab);
  CHECK(grab.tasks == std::vector<TaskId>{0});
  pool.next(1, 0.0, grab);
  CHECK(grab.tasks.empty());
}
