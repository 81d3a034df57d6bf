// Property: every strategy completes every task exactly once — over random cost tables, P
// from 1 to 64 and every registered schedule, in the simulator and in the thread engine.
#include <doctest/doctest.h>

#include <atomic>
#include <random>

#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

namespace {

std::vector<double> randomCosts(std::mt19937& rng, std::size_t n) {
  std::uniform_real_distribution<double> cost(0.01, 5.0);
  std::vector<double> costs(n);
  for (double& c : costs) c = cost(rng);
  return costs;
}

}  // namespace

TEST_CASE("Scheduler: every strategy runs every task exactly once in the simulator, P = 1..64") {
  std::mt19937 rng(12345);
  for (const ScheduleInfo& info : schedules()) {
    for (int pes : {1, 2, 3, 5, 8, 13, 31, 64}) {
      for (int grain : {1, 3}) {
        const std::size_t n = std::uniform_int_distribution<std::size_t>(0, 300)(rng);
        const Workload w = pr::test::workloadOf(randomCosts(rng, n));
        SimOptions options;
        options.pes = pes;
        options.params.grain = grain;
        options.params.bufferDepth = 1 + pes % 3;
        options.params.staticFraction = 0.3;
        options.recordTimeline = true;
        const RunRecord r = simulate(w, info.name, options);
        std::vector<int> runs(n, 0);
        for (const TaskSpan& s : r.timeline) runs[s.task] += 1;
        CAPTURE(info.name);
        CAPTURE(pes);
        CAPTURE(n);
        CHECK(std::count(runs.begin(), runs.end(), 1) == static_cast<long>(n));
        std::uint64_t tasks = 0;
        for (const PeStageRecord& pe : r.stages[0].pes) {
          tasks += pe.tasks;
          CHECK(pe.busySeconds <= r.wallSeconds + 1e-9);
        }
        CHECK(tasks == n);
      }
    }
  }
}

TEST_CASE("Scheduler: every strategy runs every task exactly once in the thread engine") {
  std::mt19937 rng(777);
  for (const ScheduleInfo& info : schedules()) {
    for (int pes : {1, 2, 7, 64}) {
      const std::size_t n = std::uniform_int_distribution<std::size_t>(0, 500)(rng);
      const TaskSet tasks = TaskSet::fromCosts(randomCosts(rng, n));
      std::vector<std::atomic<int>> runs(n);
      ScheduleParams params;
      params.grain = 1 + pes % 4;
      Runtime rt(pes, std::string(info.name), params);
      rt.runStage("property", tasks, [&](Pe&, TaskId id) { runs[id].fetch_add(1, std::memory_order_relaxed); });
      CAPTURE(info.name);
      CAPTURE(pes);
      int once = 0;
      for (auto& r : runs) once += r.load() == 1;
      CHECK(once == static_cast<int>(n));
      std::uint64_t total = 0;
      for (const PeStageRecord& pe : rt.record().stages[0].pes) total += pe.tasks;
      CHECK(total == n);
    }
  }
}
