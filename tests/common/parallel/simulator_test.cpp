// Simulator: predictions of recorded thread-engine runs, networks, cost tables, and the
// `parrender simulate` command (table on success, exit status 2 on bad input).
#include <doctest/doctest.h>

#include <fstream>

#include "common/parallel/metrics.h"
#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "common/parallel/spin_work.h"
#include "common/util/error.h"
#include "tests/common/parallel/parallel_test_support.h"
#include "tests/test_support.h"

using namespace pr::par;

TEST_CASE("Simulator: predicts a recorded thread-engine run at P = 1 and P = 2") {
  // 40 spinning tasks of 0.25 to 1 ms. The simulator replays the record's measured task costs
  // with the same schedule; it must land near the measured wall time. The benchmark prints the
  // ratio (target within 10%); here the bound is loose (50%) so a noisy CI machine cannot fail it.
  std::vector<double> costs(40);
  for (std::size_t i = 0; i < costs.size(); ++i) costs[i] = 0.25e-3 * (1 + i % 4);
  for (int pes : {1, 2}) {
    for (const char* schedule : {"demand", "balanced"}) {
      CAPTURE(pes);
      CAPTURE(schedule);
      Runtime rt(pes, schedule);
      rt.runStage("spin", TaskSet::fromCosts(costs), [&](Pe&, TaskId id) { spinFor(costs[id]); });
      const Workload w = workloadFromRecord(rt.record(), "test");
      SimOptions options;
      options.pes = pes;
      options.network = networkByName("shared-memory");
      const RunRecord predicted = simulate(w, schedule, options);
      const double measured = rt.record().wallSeconds;
      CHECK(predicted.wallSeconds == doctest::Approx(measured).epsilon(0.5));
      CHECK(predicted.wallSeconds <= measured);  // replayed task time cannot exceed the wall it was measured in
    }
  }
}

TEST_CASE("Simulator: slower networks cost more, and zero cost is exact") {
  const Workload w = pr::test::workloadOf(std::vector<double>(64, 1e-3));
  SimOptions options;
  options.pes = 8;
  double previous = 0.0;
  for (const char* net : {"zero", "shared-memory", "10gbe", "1gbe", "100mbit"}) {
    options.network = networkByName(net);
    const double t = simulate(w, "demand", options).wallSeconds;
    CAPTURE(net);
    CHECK(t >= previous);
    previous = t;
  }
  options.network = networkByName("zero");
  CHECK(simulate(w, "demand", options).wallSeconds == doctest::Approx(8e-3));
  // 100 Mbit: each request + packet is 2 ms of latency plus 32 bytes at 12.5 MB/s on top of 1 ms.
  options.network = networkByName("100mbit");
  CHECK(simulate(w, "demand", options).wallSeconds == doctest::Approx(8 * (3e-3 + 40.0 / 12.5e6)));
  CHECK_THROWS_AS(networkByName("token-ring"), pr::InputError);
}

TEST_CASE("Simulator: data messages a task sent are charged to the sender") {
  pr::par::Workload w = pr::test::workloadOf({1.0, 1.0});
  w.stages[0].messages = {2, 0};
  w.stages[0].bytes = {1000, 0};
  SimOptions options;
  options.pes = 1;
  options.network = NetworkModel{"t", 0.25, 1000.0, ""};
  options.params.grain = 2;
  const RunRecord r = simulate(w, "balanced", options);
  // One static packet (1 message, 16 + 2 * 8 bytes), then task 0 pays 2 * 0.25 + 1000 / 1000.
  CHECK(r.wallSeconds == doctest::Approx(0.25 + 32.0 / 1000.0 + 1.0 + 1.5 + 1.0));
  CHECK(r.stages[0].pes[0].messagesSent == 2);
  CHECK(r.stages[0].pes[0].bytesSent == 1000);
}

TEST_CASE("Simulator: cost tables name the line of a bad entry") {
  const Workload w = workloadFromCostTable("# costs\n0.5\n1.5 2 3\n\n2,4,5\n", "t.txt");
  REQUIRE(w.stages[0].costs == std::vector<double>{0.5, 1.5, 2.0});
  CHECK(w.stages[0].tasks.tasks[1].x == 2.0f);
  CHECK(w.stages[0].tasks.tasks[2].y == 5.0f);
  CHECK_THROWS_WITH_AS(workloadFromCostTable("1\nabc\n", "t.txt"), "t.txt, line 2: expected a task cost in seconds",
                       pr::InputError);
  CHECK_THROWS_AS(workloadFromCostTable("1 2\n", "t.txt"), pr::InputError);
  CHECK_THROWS_AS(workloadFromCostTable("-1\n", "t.txt"), pr::InputError);
  CHECK_THROWS_AS(workloadFromCostTable("# nothing\n", "t.txt"), pr::InputError);
}

TEST_CASE("Simulator: a record without a timeline cannot be replayed") {
  RuntimeOptions options;
  options.pes = 2;
  options.recordTimeline = false;
  Runtime rt(options);
  rt.runStage("s", TaskSet::uniform(4), [](Pe&, TaskId) {});
  CHECK_THROWS_AS(workloadFromRecord(rt.record(), "r.json"), pr::InputError);
}

TEST_CASE("Simulator: parrender simulate prints a table from a run record and a cost table") {
  const auto dir = pr::test::scratchDir("simulate_cli");
  Runtime rt(2, "demand");
  rt.runStage("spin", TaskSet::uniform(16), [](Pe&, TaskId) { spinFor(1e-4); });
  writeRunRecord(rt.record(), dir / "run.json");
  auto result = pr::test::runParrender("simulate " + (dir / "run.json").string() + " --pes 1,2,4,...,64 --network 10gbe");
  CHECK(result.exitStatus == 0);
  CHECK(result.output.find("recorded run: P = 2, schedule demand") != std::string::npos);
  CHECK(result.output.find("\n    64 ") != std::string::npos);
  CHECK(result.output.find("best P:") != std::string::npos);

  std::ofstream(dir / "costs.txt") << "1\n1\n3\n4\n4\n3\n3\n2\n1\n2\n2\n2\n2\n2\n1\n1\n1\n1\n1\n1\n1\n1\n1\n1\n";
  result = pr::test::runParrender("simulate " + (dir / "costs.txt").string() + " --pes 3 --network zero --schedule balanced");
  CHECK(result.exitStatus == 0);
  CHECK(result.output.find("     3      21.000000") != std::string::npos);

  result = pr::test::runParrender("simulate " + (dir / "costs.txt").string() + " --network carrier-pigeon");
  CHECK(result.exitStatus == 2);
  CHECK(result.output.find("unknown network 'carrier-pigeon'") != std::string::npos);
  result = pr::test::runParrender("simulate " + (dir / "costs.txt").string() + " --pes 1,2000");
  CHECK(result.exitStatus == 2);
  CHECK(result.output.find("P must be in [1, 1024]") != std::string::npos);
  std::ofstream(dir / "bad.json") << "{\"pes\": 2, \"stages\": 3}";
  result = pr::test::runParrender("simulate " + (dir / "bad.json").string());
  CHECK(result.exitStatus == 2);
  CHECK(result.output.find("\"stages\" must be an array") != std::string::npos);
}
