// Allocation orders of the demand-driven supplier: serial, spiral, random, hot-spots.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>

#include "common/parallel/schedulers/task_order.h"

using namespace pr::par;

TEST_CASE("TaskOrder: spiral starts with the four centre tiles of a 4x4 grid, then the ring") {
  const TaskSet grid = TaskSet::grid(4, 4);
  const auto order = taskOrder(grid, TaskOrder::Spiral);
  REQUIRE(order.size() == 16);
  // Centre (2, 2); the inner ring is tiles (1,1) (2,1) (1,2) (2,2) = ids 5 6 9 10, by angle
  // from +x counter-clockwise (y down in image space): 10 (45deg), 9 (135), 5 (225), 6 (315).
  CHECK(std::vector<TaskId>(order.begin(), order.begin() + 4) == std::vector<TaskId>{10, 9, 5, 6});
  std::vector<TaskId> rest(order.begin() + 4, order.end());
  for (TaskId inner : {5, 6, 9, 10}) CHECK(std::find(rest.begin(), rest.end(), inner) == rest.end());
}

TEST_CASE("TaskOrder: random is a permutation, fixed by its seed") {
  const TaskSet set = TaskSet::uniform(1000);
  const auto a = taskOrder(set, TaskOrder::Random, 7), b = taskOrder(set, TaskOrder::Random, 7);
  const auto c = taskOrder(set, TaskOrder::Random, 8);
  CHECK(a == b);
  CHECK(a != c);
  auto sorted = a;
  std::sort(sorted.begin(), sorted.end());
  std::vector<TaskId> ids(1000);
  std::iota(ids.begin(), ids.end(), TaskId{0});
  CHECK(sorted == ids);
  CHECK(a != ids);
}

TEST_CASE("TaskOrder: hot-spots by decreasing estimate, ties in image order; serial is identity") {
  const TaskSet set = TaskSet::fromCosts({1, 5, 2, 5, 3});
  CHECK(taskOrder(set, TaskOrder::HotSpots) == std::vector<TaskId>{1, 3, 4, 2, 0});
  CHECK(taskOrder(set, TaskOrder::Serial) == std::vector<TaskId>{0, 1, 2, 3, 4});
}
