// Distributed task management (seed 3.4.4): an idle PE takes half of a neighbour's pool.
#include <doctest/doctest.h>

#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("Distributed: an idle PE takes work from its neighbour's pool, not the controller") {
  // Pools start as the balanced split: PE 0 {0..3} costs 20, PE 1 {4..7} costs 4.
  const Workload w = pr::test::workloadOf({5, 5, 5, 5, 1, 1, 1, 1});
  SimOptions options;
  options.pes = 2;
  options.recordTimeline = true;
  const RunRecord r = simulate(w, "distributed", options);
  // At t = 4 PE 1 is empty; PE 0's pool holds {1, 2, 3}: PE 1 takes the back half {2, 3} and
  // ends at 4 + 10 = 14; PE 0 ends task 1 at 10 and finds nothing left.
  CHECK(r.wallSeconds == 14.0);
  int onPe1 = 0;
  for (const TaskSpan& s : r.timeline)
    if (s.task == 2 || s.task == 3) onPe1 += s.pe == 1;
  CHECK(onPe1 == 2);
  // PE 1 received its initial pool from the controller and one packet from PE 0 (+ a request).
  CHECK(r.stages[0].pes[1].schedulingMessages == 3);
  CHECK(simulate(w, "balanced", options).wallSeconds == 20.0);
}
