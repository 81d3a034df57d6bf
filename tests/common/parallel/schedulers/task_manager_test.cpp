// Task manager with a local pool (seed 3.4.3): refills ahead of need hide the request latency;
// buffered tasks cannot move to an idle PE, the end-of-stage imbalance the seed warns about.
#include <doctest/doctest.h>

#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("TaskManager: a local pool hides the request latency after the first packet") {
  const Workload w = pr::test::workloadOf(std::vector<double>(8, 1.0));
  SimOptions options;
  options.pes = 1;
  options.network = NetworkModel{"test", 0.5, 0.0, ""};
  options.params.bufferDepth = 2;
  // Only the first packet is waited for (request + packet = 1 s); later refills arrive while
  // the PE computes. The demand-driven pool waits for every packet: 8 * (1 + 1) = 16 s.
  CHECK(simulate(w, "task-manager", options).wallSeconds == doctest::Approx(9.0));
  CHECK(simulate(w, "demand", options).wallSeconds == doctest::Approx(16.0));
  const RunRecord r = simulate(w, "task-manager", options);
  CHECK(r.stages[0].pes[0].schedulingMessages == 16);  // still a request and a packet per task
}

TEST_CASE("TaskManager: deep buffers strand tasks at a busy PE") {
  // Task 0 is long. PE 0 takes it and buffers the next 4; PE 1 drains the rest of the pool and
  // then has nothing to do while PE 0 works through its buffer after task 0.
  std::vector<double> costs(12, 1.0);
  costs[0] = 6.0;
  const Workload w = pr::test::workloadOf(costs);
  SimOptions options;
  options.pes = 2;
  options.params.bufferDepth = 4;
  const double deep = simulate(w, "task-manager", options).wallSeconds;
  options.params.bufferDepth = 1;
  const double shallow = simulate(w, "task-manager", options).wallSeconds;
  // Depth 4: PE 0 holds 1..4 behind task 0 and ends at 6 + 4 = 10; PE 1 runs 5..11 by t = 7.
  CHECK(deep == 10.0);
  // Depth 1: PE 0 holds only task 1; after task 0 it shares the tail with PE 1 and both end
  // by t = 9, as with the demand-driven pool.
  CHECK(shallow == 9.0);
  CHECK(simulate(w, "demand", options).wallSeconds == 9.0);  // 17 units of work, no buffering: 6 | 11 -> 9
}
