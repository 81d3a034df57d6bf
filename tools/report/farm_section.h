// The report's render-farm section (`report --farm` under mpirun): image-space as Jensen's
// farm beside the same method run as SPMD stages across the same ranks, each farm server's
// jobs, busy, idle and CPU time, the lost ones, and the simulator's replay of the farm's record
// at other numbers of servers on the report's network (farm_replay.h), with its residual at the
// measured number.
#pragma once

#include <string>

#include "common/parallel/simulator.h"
#include "tools/compare/comparison.h"

namespace pr::cli::report {

// "" when the comparison has no farm rows. maxServers: the largest number of servers predicted.
std::string farmSection(const Comparison& c, const par::NetworkModel& network, int maxServers);

}  // namespace pr::cli::report
