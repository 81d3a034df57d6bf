// Demand-driven task pool (seed 3.2.2): the worked example's serial allocation (figure 3.10)
// and the effect of the allocation order and grain in the simulator.
#include <doctest/doctest.h>

#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("DemandDriven: seed worked example, serial order finishes in 14 units on 3 PEs") {
  SimOptions options;
  options.pes = 3;
  options.recordTimeline = true;
  const RunRecord r = simulate(pr::test::seedExample(), "demand", options);
  CHECK(r.wallSeconds == 14.0);
  // Figure 3.10: PE 0 takes tasks 1 and 2... in image order; the first three requests at t = 0
  // go to PEs 0, 1, 2 (ties by PE id), and task 3 (cost 3) keeps PE 2 busy until t = 3.
  REQUIRE(r.timeline.size() == 24);
  CHECK(r.timeline[0].task == 0);
  CHECK(r.timeline[0].pe == 0);
  CHECK(r.timeline[2].pe == 2);
  CHECK(r.timeline[2].end == 3.0);
}

TEST_CASE("DemandDriven: hot-spots first never does worse than serial on a late hot spot") {
  // One expensive task at the end of image order: serial hands it out last, hot-spots first.
  std::vector<double> costs(30, 1.0);
  costs.back() = 10.0;
  SimOptions options;
  options.pes = 4;
  const Workload w = pr::test::workloadOf(costs);
  const double serial = simulate(w, "demand", options).wallSeconds;
  const double hot = simulate(w, "hot-spots", options).wallSeconds;
  // Serial: 29 unit tasks spread over 4 PEs, the hot task starts at t = 7 and ends at 17.
  CHECK(serial == 17.0);
  // Hot-spots: the 10-unit task starts at 0 on PE 0; 29 units on the other three end by 10.
  CHECK(hot == 10.0);
}

TEST_CASE("DemandDriven: grain sets the task packet size and the scheduling traffic") {
  const Workload w = pr::test::workloadOf(std::vector<double>(100, 1.0));
  SimOptions options;
  options.pes = 4;
  options.params.grain = 10;
  const RunRecord r = simulate(w, "demand", options);
  std::uint64_t packets = 0, bytes = 0;
  for (const PeStageRecord& pe : r.stages[0].pes) packets += pe.schedulingMessages, bytes += pe.schedulingBytes;
  // 10 packets of 10 tasks, each a request plus a packet.
  CHECK(packets == 20);
  CHECK(bytes == 10 * (kTaskRequestBytes + kTaskPacketHeaderBytes) + 100 * kTaskEntryBytes);
  // Packets of 10 on 4 PEs: 10 packets in rounds of 4 -> 3 rounds -> 30 units.
  CHECK(r.wallSeconds == 30.0);
}

TEST_CASE("DemandDriven: with a network model every blocking request costs a round trip") {
  const Workload w = pr::test::workloadOf(std::vector<double>(8, 1.0));
  SimOptions options;
  options.pes = 1;
  options.network = NetworkModel{"test", 0.5, 0.0, ""};
  const RunRecord r = simulate(w, "demand", options);
  // 8 requests, each a request and a packet at 0.5 s latency: 8 * (1 + 1) = 16 s.
  CHECK(r.wallSeconds == doctest::Approx(16.0));
  CHECK(r.stages[0].pes[0].idleSeconds == doctest::Approx(8.0));
}
