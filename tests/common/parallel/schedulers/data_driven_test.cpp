// Data-driven models against the seed's worked example (section 3.2.1): 24 tasks on 3 PEs,
// total cost 42 units, in the simulator with zero communication cost, where the makespans are
// exact; and the thread engine hands out exactly the simulator's assignment.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <set>

#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("DataDriven: balanced split gives the first n mod P PEs one extra contiguous task") {
  const auto portions = balancedSplit(24, 5);
  REQUIRE(portions.size() == 5);
  CHECK(portions[0] == std::vector<TaskId>{0, 1, 2, 3, 4});
  CHECK(portions[3].size() == 5);
  CHECK(portions[4] == std::vector<TaskId>{20, 21, 22, 23});
}

TEST_CASE("DataDriven: seed worked example, balanced makespan 21 and unbalanced 14 on 3 PEs") {
  const Workload w = pr::test::seedExample();
  double total = 0.0;
  for (double c : w.stages[0].costs) total += c;
  CHECK(total == 42.0);
  SimOptions options;
  options.pes = 3;
  // Balanced: portions 1..8, 9..16, 17..24 cost 21, 13 and 8.
  const RunRecord balanced = simulate(w, "balanced", options);
  CHECK(balanced.wallSeconds == 21.0);
  CHECK(balanced.stages[0].pes[1].busySeconds == 13.0);
  CHECK(balanced.stages[0].pes[2].busySeconds == 8.0);
  // Unbalanced: every PE gets 42 / 3 = 14 units of estimated work.
  const RunRecord unbalanced = simulate(w, "unbalanced", options);
  CHECK(unbalanced.wallSeconds == 14.0);
  for (const PeStageRecord& pe : unbalanced.stages[0].pes) CHECK(pe.busySeconds == 14.0);
}

TEST_CASE("DataDriven: 24 unit tasks on 5 PEs take 5 units (four PEs do 5 tasks, one does 4)") {
  Workload w = pr::test::workloadOf(std::vector<double>(24, 1.0));
  SimOptions options;
  options.pes = 5;
  const RunRecord r = simulate(w, "balanced", options);
  CHECK(r.wallSeconds == 5.0);
  CHECK(r.stages[0].pes[4].tasks == 4);
  CHECK(r.stages[0].pes[4].syncWaitSeconds == 1.0);
}

TEST_CASE("DataDriven: the thread engine runs exactly the simulator's assignment") {
  const Workload w = pr::test::seedExample();
  for (const char* schedule : {"balanced", "unbalanced", "hybrid"}) {
    CAPTURE(schedule);
    SimOptions options;
    options.pes = 3;
    options.recordTimeline = true;
    const RunRecord simulated = simulate(w, schedule, options);
    // hybrid's static half is data-driven; its demand half is not, so compare only that part.
    Runtime rt(3, schedule);
    rt.runStage("example", w.stages[0].tasks, [](Pe&, TaskId) {});
    auto owners = [](const RunRecord& r) {
      std::map<TaskId, int> owner;
      for (const TaskSpan& s : r.timeline) owner[s.task] = s.pe;
      return owner;
    };
    auto sim = owners(simulated), real = owners(rt.record());
    REQUIRE(real.size() == 24);
    if (std::string(schedule) == "hybrid") {
      for (TaskId id = 0; id < 12; ++id) CHECK(real[id] == sim[id]);
    } else {
      CHECK(real == sim);
    }
  }
}

TEST_CASE("DataDriven: an unbalanced split from the profile of an earlier run") {
  // An earlier demand-driven run recorded each task's cost; the next run splits by it. Without
  // it (every estimate 1) the unbalanced split can only give each PE 8 tasks and misses 14.
  Workload w = pr::test::seedExample();
  for (TaskInfo& t : w.stages[0].tasks.tasks) t.costEstimate = 1.0;
  SimOptions options;
  options.pes = 3;
  options.recordTimeline = true;
  const RunRecord earlier = simulate(w, "demand", options);
  const RunRecord blind = simulate(w, "unbalanced", options);
  CHECK(blind.wallSeconds > 14.0);
  for (const PeStageRecord& pe : blind.stages[0].pes) CHECK(pe.tasks == 8);
  const std::vector<double> profile = taskCostProfile(earlier, 0);
  CHECK(profile == pr::test::seedExampleCosts());
  for (std::size_t i = 0; i < profile.size(); ++i) w.stages[0].tasks.tasks[i].costEstimate = profile[i];
  CHECK(simulate(w, "unbalanced", options).wallSeconds == 14.0);
}
