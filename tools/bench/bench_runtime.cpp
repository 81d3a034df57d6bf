// bench_runtime: figures of the parallel runtime (common/parallel), outside the test suite.
// Prints, with the anchor of each ratio measured in the same run:
//  1. the seed's worked example (24 tasks, 42 units) with spinning busy work in the thread
//     engine for every strategy, beside the simulator's makespans;
//  2. scheduling overhead per task for every strategy at P = 2 (target < 1 us, demand pool),
//     and the effect of the grain (task packet size) on efficiency and request traffic;
//  3. parallel efficiency at P = 2 on an embarrassingly parallel workload (target >= 97%);
//  4. the simulator's prediction of recorded runs at P = 1 and 2 (target within 10%);
//  5. simulator speed in simulated tasks per second (target >= 1M);
//  6. the fixed cost of one stage (start, barrier, record) at P = 1, 2 and 4, beside the cost
//     of one empty task, as a raster frame runs two to five stages.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/parallel/metrics.h"
#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "common/parallel/spin_work.h"
#include "common/util/allocator.h"

using namespace pr::par;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Workload workloadOf(const std::vector<double>& costs) {
  Workload w;
  SimStage stage;
  stage.name = "costs";
  stage.tasks = TaskSet::fromCosts(costs);
  stage.costs = costs;
  w.stages.push_back(stage);
  return w;
}

// Runs costs (seconds) as spinning tasks; returns the run record.
RunRecord runSpin(int pes, const std::string& schedule, const std::vector<double>& costs, ScheduleParams params = {}) {
  Runtime rt(pes, schedule, params);
  rt.runStage("spin", TaskSet::fromCosts(costs), [&](Pe&, TaskId id) { spinFor(costs[id]); });
  return rt.record();
}

void workedExample(int pes, double unitSeconds) {
  const std::vector<double> units = {1, 1, 3, 4, 4, 3, 3, 2, 1, 2, 2, 2, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  std::vector<double> costs;
  for (double u : units) costs.push_back(u * unitSeconds);
  std::printf("\n1. seed worked example, P = %d, 1 unit = %.1f ms of spinning (makespans in units)\n", pes,
              unitSeconds * 1e3);
  std::printf("%-15s %10s %10s %8s\n", "schedule", "simulated", "measured", "ratio");
  const Workload w = workloadOf(units);
  for (const ScheduleInfo& s : schedules()) {
    SimOptions options;
    options.pes = pes;
    const double simulated = simulate(w, s.name, options).wallSeconds;
    const double measured = runSpin(pes, std::string(s.name), costs).wallSeconds / unitSeconds;
    std::printf("%-15s %10.2f %10.2f %8.3f\n", std::string(s.name).c_str(), simulated, measured, measured / simulated);
  }
}

void schedulingOverhead() {
  const std::size_t n = 200000;
  std::printf("\n2. scheduling overhead, P = 2, %zu empty tasks, grain 1, no timeline (PE time per task)\n", n);
  std::printf("%-15s %12s %14s\n", "schedule", "wall/task", "P*wall/task");
  const TaskSet tasks = TaskSet::uniform(n);
  for (const ScheduleInfo& s : schedules()) {
    RuntimeOptions options;
    options.pes = 2;
    options.schedule = std::string(s.name);
    options.recordTimeline = false;
    Runtime rt(options);
    rt.runStage("empty", tasks, [](Pe&, TaskId) {});  // warm-up: thread start, page faults
    const auto t0 = std::chrono::steady_clock::now();
    rt.runStage("empty", tasks, [](Pe&, TaskId) {});
    const double wall = secondsSince(t0);
    std::printf("%-15s %9.3f us %11.3f us\n", std::string(s.name).c_str(), wall / n * 1e6, 2 * wall / n * 1e6);
  }
  Runtime rt(2, "demand");
  const auto t0 = std::chrono::steady_clock::now();
  rt.runStage("empty", tasks, [](Pe&, TaskId) {});
  std::printf("%-15s %9.3f us %11.3f us  (demand, timeline recorded)\n", "demand+spans", secondsSince(t0) / n * 1e6,
              2 * secondsSince(t0) / n * 1e6);
}

void granularity() {
  // Larger packets mean fewer requests but a coarser end of stage: the seed's granularity trade.
  std::vector<double> costs(4000);
  for (std::size_t i = 0; i < costs.size(); ++i) costs[i] = 20e-6 * (1 + i % 5);
  std::printf("\n2b. granularity, demand-driven, P = 2, 4000 tasks of 20..100 us\n");
  std::printf("%6s %10s %8s %10s %12s\n", "grain", "wall s", "utilis.", "imbalance", "sched. msgs");
  for (int grain : {1, 4, 16, 64, 256, 1000}) {
    ScheduleParams params;
    params.grain = grain;
    const RunSummary s = summarize(runSpin(2, "demand", costs, params));
    std::printf("%6d %10.5f %8.4f %10.4f %12llu\n", grain, s.wallSeconds, s.total.utilisation, s.total.imbalance,
                (unsigned long long)s.total.schedulingMessages);
  }
}

void efficiency() {
  const std::vector<double> costs(400, 1e-3);
  std::printf("\n3. parallel efficiency, 400 tasks of 1 ms spinning (embarrassingly parallel)\n");
  std::vector<ScalingPoint> points;
  const int maxPes = std::max(2u, std::min(8u, std::thread::hardware_concurrency()));
  for (int pes = 1; pes <= maxPes; pes *= 2) {
    const RunRecord r = runSpin(pes, "demand", costs);
    const RunSummary s = summarize(r);
    points.push_back({pes, r.wallSeconds});
    std::printf("P = %d: wall %.4f s, busy/(P*wall) %.2f%%, imbalance %.4f\n", pes, r.wallSeconds,
                100 * s.total.utilisation, s.total.imbalance);
  }
  const double serial = 400 * 1e-3;  // Ts: the same spinning without the runtime
  const ScalingTable table = scalingTable(points, serial);
  std::printf("%s", formatScaling(table).c_str());
  std::printf("efficiency T1/(2*T2) at P = 2: %.2f%% (target >= 97%%)\n", 100 * table.rows[1].efficiency);
}

void prediction() {
  std::vector<double> costs(200);
  for (std::size_t i = 0; i < costs.size(); ++i) costs[i] = 0.5e-3 * (1 + (i * 7) % 5);
  std::printf("\n4. simulator vs thread engine (same schedule, recorded task costs, shared-memory network)\n");
  std::printf("%-15s %3s %12s %12s %8s %22s\n", "schedule", "P", "measured s", "predicted s", "ratio",
              "P=2 from P=1 record");
  for (const char* schedule : {"balanced", "unbalanced", "demand", "task-manager", "distributed", "preferred-bias"}) {
    const RunRecord one = runSpin(1, schedule, costs);
    const Workload fromOne = workloadFromRecord(one, "P=1 run");
    for (int pes : {1, 2}) {
      const RunRecord measured = pes == 1 ? one : runSpin(pes, schedule, costs);
      SimOptions options;
      options.pes = pes;
      options.network = networkByName("shared-memory");
      const double predicted = simulate(workloadFromRecord(measured, "run"), schedule, options).wallSeconds;
      char cross[32] = "";
      if (pes == 2)
        std::snprintf(cross, sizeof cross, "%.3f", simulate(fromOne, schedule, options).wallSeconds / measured.wallSeconds);
      std::printf("%-15s %3d %12.5f %12.5f %8.3f %22s\n", schedule, pes, measured.wallSeconds, predicted,
                  predicted / measured.wallSeconds, cross);
    }
  }
}

void simulatorSpeed() {
  const std::size_t n = 1 << 20;
  std::vector<double> costs(n);
  for (std::size_t i = 0; i < n; ++i) costs[i] = 1e-3 * (1 + i % 13);
  const Workload w = workloadOf(costs);
  std::printf("\n5. simulator speed, %zu tasks\n", n);
  for (const char* schedule : {"demand", "balanced", "distributed", "preferred-bias"}) {
    for (int pes : {64, 1024}) {
      SimOptions options;
      options.pes = pes;
      options.network = networkByName("10gbe");
      const auto t0 = std::chrono::steady_clock::now();
      const RunRecord r = simulate(w, schedule, options);
      const double seconds = secondsSince(t0);
      std::printf("%-15s P = %4d: %.3f s, %.1f M simulated tasks/s (makespan %.3f s)\n", schedule, pes, seconds,
                  n / seconds / 1e6, r.wallSeconds);
    }
  }
}

void stageOverhead() {
  const int stages = 2000;
  std::printf("\n6. stage overhead, %d stages of P empty tasks each (per stage, median of 5 rounds)\n", stages);
  std::printf("%3s %14s %16s\n", "P", "per stage", "per stage / task");
  for (int pes : {1, 2, 4}) {
    RuntimeOptions options;
    options.pes = pes;
    options.schedule = "balanced";
    options.recordTimeline = false;
    Runtime rt(options);
    const TaskSet tasks = TaskSet::uniform(static_cast<std::size_t>(pes));
    rt.runStage("warm-up", tasks, [](Pe&, TaskId) {});
    std::vector<double> rounds;
    for (int round = 0; round < 5; ++round) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int s = 0; s < stages; ++s) rt.runStage("empty", tasks, [](Pe&, TaskId) {});
      rounds.push_back(secondsSince(t0) / stages);
    }
    std::sort(rounds.begin(), rounds.end());
    // The anchor in the same run: one empty task under the demand pool (section 2's figure).
    Runtime pool(RuntimeOptions{pes, "demand", ScheduleParams(), false});
    const TaskSet many = TaskSet::uniform(100000);
    const auto t1 = std::chrono::steady_clock::now();
    pool.runStage("empty", many, [](Pe&, TaskId) {});
    const double perTask = secondsSince(t1) / 100000;
    std::printf("%3d %11.2f us %16.0f\n", pes, rounds[2] * 1e6, rounds[2] / perTask);
  }
}

}  // namespace

int main(int argc, char** argv) {
  pr::retainFreedMemory();
  CLI::App app{"bench_runtime: the parallel runtime's worked examples, scheduling overhead, granularity, efficiency and the simulator's prediction and speed"};
  CLI11_PARSE(app, argc, argv);
  std::printf("bench_runtime: %u hardware threads\n", std::thread::hardware_concurrency());
  workedExample(3, 5e-3);
  workedExample(2, 5e-3);
  schedulingOverhead();
  granularity();
  efficiency();
  prediction();
  simulatorSpeed();
  stageOverhead();
  return 0;
}
