// Hybrid computational model (seed 3.2.3): a static first portion, then on demand.
#include <doctest/doctest.h>

#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("Hybrid: the static portion is split without requests, the rest is demanded") {
  const Workload w = pr::test::workloadOf(std::vector<double>(8, 1.0));
  SimOptions options;
  options.pes = 2;
  options.params.staticFraction = 0.5;
  options.recordTimeline = true;
  const RunRecord r = simulate(w, "hybrid", options);
  std::vector<int> pe(8, -1);
  for (const TaskSpan& s : r.timeline) pe[s.task] = s.pe;
  CHECK(pe[0] == 0);
  CHECK(pe[1] == 0);
  CHECK(pe[2] == 1);
  CHECK(pe[3] == 1);
  CHECK(r.wallSeconds == 4.0);
  // Per PE: one static packet (1 message) and two demanded tasks (request + packet each).
  for (const PeStageRecord& p : r.stages[0].pes) CHECK(p.schedulingMessages == 1 + 2 * 2);
}
