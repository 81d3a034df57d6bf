// Preferred-bias allocation (seed 3.4.5): conceptual regions handed out on demand; a PE that
// finishes its region helps the region with the most estimated work left, from its back end.
#include <doctest/doctest.h>

#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("PreferredBias: PEs keep to their region, then help the one with most work left") {
  // Regions: PE 0 {0..3} (cost 20), PE 1 {4..7} (4), PE 2 {8..11} (8).
  const Workload w = pr::test::workloadOf({5, 5, 5, 5, 1, 1, 1, 1, 2, 2, 2, 2});
  SimOptions options;
  options.pes = 3;
  options.recordTimeline = true;
  const RunRecord r = simulate(w, "preferred-bias", options);
  std::vector<int> pe(12, -1);
  for (const TaskSpan& s : r.timeline) pe[s.task] = s.pe;
  for (int id = 4; id < 8; ++id) CHECK(pe[id] == 1);
  for (int id = 8; id < 12; ++id) CHECK(pe[id] == 2);
  // PE 1 is done at t = 4 and helps region 0 (tasks 1..3 left, most work): takes task 3.
  CHECK(pe[3] == 1);
  CHECK(pe[0] == 0);
  CHECK(pe[1] == 0);
  // PE 2 is done at t = 8 with task 2 still unallocated (PE 0 took 1 at t = 5): it takes it.
  CHECK(pe[2] == 2);
  CHECK(r.wallSeconds == 13.0);  // PE 2: 8 + 5
}

TEST_CASE("PreferredBias: a task's preferred PE puts it in that PE's region, the others keep their portion") {
  // Tasks 0..5; 0, 2 and 4 prefer PE 1 and 5 prefers PE 0; 1 and 3 name none and stay in the
  // balanced portion they fall in (PE 0: 0..2, PE 1: 3..5). Regions: PE 0 {1, 5} (cost 1
  // each), PE 1 {0, 2, 3, 4} (1.5 each; no two PEs free at once, so no tie decides). PE 0
  // finishes its region at t = 2 and helps PE 1 from its back: task 4 (PE 1 is on task 2).
  Workload w = pr::test::workloadOf({1.5, 1, 1.5, 1.5, 1.5, 1});
  for (int id : {0, 2, 4}) w.stages[0].tasks.tasks[size_t(id)].preferredPe = 1;
  w.stages[0].tasks.tasks[5].preferredPe = 0;
  SimOptions options;
  options.pes = 2;
  options.recordTimeline = true;
  const RunRecord r = simulate(w, "preferred-bias", options);
  std::vector<int> pe(6, -1);
  for (const TaskSpan& s : r.timeline) pe[size_t(s.task)] = s.pe;
  CHECK(pe == std::vector<int>{1, 0, 1, 1, 0, 0});
  CHECK(r.wallSeconds == doctest::Approx(4.5));  // PE 1: 0, 2, 3
  // A preference outside [0, P) names no PE here: each PE keeps to its contiguous half.
  for (TaskInfo& t : w.stages[0].tasks.tasks) t.preferredPe = 7;
  const RunRecord plain = simulate(w, "preferred-bias", options);
  std::vector<int> first(6, -1);
  for (const TaskSpan& s : plain.timeline) first[size_t(s.task)] = s.pe;
  CHECK(first == std::vector<int>{0, 0, 0, 1, 1, 1});
}
