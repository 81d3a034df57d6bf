// Distributed task management (seed 3.4.4): an idle PE takes half of a neighbour's pool.
#include <doctest/doctest.h>

#include "common/parallel/runtime.h"
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
  // PE 1 received its initial pool from the controller and one packet from PE 0 (+ a request),
  // and at t = 14 asked PE 0 again, answered empty (a request and an empty packet).
  CHECK(r.stages[0].pes[1].schedulingMessages == 5);
  CHECK(simulate(w, "balanced", options).wallSeconds == 20.0);
}

TEST_CASE("Distributed: a steal request answered empty is a request and a packet, and a round trip in the simulator") {
  // 4 PEs, 2 tasks of 1 s each in every pool: all finish at the same time, and each PE's last
  // search asks the 3 others (at distances 1, 1 and 2 around the ring) and finds them empty.
  const Workload w = pr::test::workloadOf({1, 1, 1, 1, 1, 1, 1, 1});
  SimOptions options;
  options.pes = 4;
  options.network = NetworkModel{"test", 0.5, 0.0, ""};
  const RunRecord r = simulate(w, "distributed", options);
  for (int p = 0; p < 4; ++p) {
    CAPTURE(p);
    // The initial packet, and 3 requests with their empty answers.
    CHECK(r.stages[0].pes[std::size_t(p)].schedulingMessages == 1 + 3 * 2);
  }
  // The initial packet 0.5 s, the tasks 2 s, the 3 round trips 3 s.
  CHECK(r.wallSeconds == doctest::Approx(0.5 + 2.0 + 3.0));

  // The thread runtime books them too: every PE's last search asked each other PE once (a
  // task in each pool, none left to steal once each PE runs its own: 2 requests, 2 answers).
  pr::test::runWithTimeout(
      [] {
        Runtime rt(3, "distributed");
        rt.runStage("stage", TaskSet::uniform(3), [](Pe&, TaskId) { std::this_thread::sleep_for(std::chrono::milliseconds(2)); });
        for (int p = 0; p < 3; ++p) {
          CAPTURE(p);
          CHECK(rt.record().stages[0].pes[std::size_t(p)].schedulingMessages >= 2 * 2);
        }
      },
      60.0, "Distributed: empty answers booked");
}
