// Helpers shared by the runtime tests: the seed's worked example as a workload, workloads from
// cost lists, and a guard that ends the test binary if a run hangs instead of blocking CI.
#pragma once

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <future>
#include <memory>
#include <thread>
#include <vector>

#include "common/parallel/simulator.h"

namespace pr::test {

inline par::Workload workloadOf(const std::vector<double>& costs) {
  par::Workload w;
  par::SimStage stage;
  stage.name = "costs";
  stage.tasks = par::TaskSet::fromCosts(costs);
  stage.costs = costs;
  w.stages.push_back(stage);
  return w;
}

// Seed section 3.2, figures 3.6-3.10: 24 pixels in image order, costs in time units.
inline std::vector<double> seedExampleCosts() {
  return {1, 1, 3, 4, 4, 3, 3, 2, 1, 2, 2, 2, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
}
inline par::Workload seedExample() { return workloadOf(seedExampleCosts()); }

// Runs fn on its own thread; if it has not returned after `seconds`, reports and exits the
// process (a hung runtime cannot be unwound, and a test must never block CI).
inline void runWithTimeout(std::function<void()> fn, double seconds, const char* what) {
  auto done = std::make_shared<std::promise<void>>();
  std::future<void> finished = done->get_future();
  std::thread([fn = std::move(fn), done] {
    try {
      fn();
      done->set_value();
    } catch (...) {
      done->set_exception(std::current_exception());
    }
  }).detach();
  if (finished.wait_for(std::chrono::duration<double>(seconds)) != std::future_status::ready) {
    std::fprintf(stderr, "TIMEOUT: %s did not finish within %.0f s (hang)\n", what, seconds);
    std::_Exit(3);
  }
  finished.get();  // rethrows what fn threw
}

}  // namespace pr::test
