// Orders in which a demand-driven task supplier hands out tasks (seed 3.2.2, figures 3.10 and
// 3.11): serial (image order), spiral from the image centre, random, and hot-spots first by
// cost estimate. Pure functions of the TaskSet, so every run and the simulator agree.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "common/parallel/task.h"

namespace pr::par {

enum class TaskOrder { Serial, Spiral, Random, HotSpots };

std::string_view toString(TaskOrder order);

// A permutation of [0, tasks.size()).
// Spiral: square rings around the centre of the positions' bounding box, inner rings first;
// within a ring by angle counter-clockwise from +x; ties by id.
// Random: Fisher-Yates driven by splitmix64(seed), identical on every platform.
// HotSpots: decreasing cost estimate, ties in image order.
std::vector<TaskId> taskOrder(const TaskSet& tasks, TaskOrder order, std::uint64_t seed = 1);

}  // namespace pr::par
