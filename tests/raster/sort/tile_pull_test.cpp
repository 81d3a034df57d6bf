// TilePull: the pull protocol of dynamic regions (raster/sort/tile_pull.h). A PE taking a tile
// gathers every PE's bin of it; when another PE's task fails, the waiting PE stops instead of
// waiting for a reply that never comes, and the stage ends with the original error.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/parallel/runtime.h"
#include "raster/sort/region_assignment.h"
#include "raster/sort/tile_pull.h"
#include "tests/common/parallel/parallel_test_support.h"

namespace pr::raster {
namespace {

using Bins = std::vector<std::vector<std::vector<int>>>;  // bins[pe][tile]

// bins[p][t] = {10 p + t}: whoever gathers tile t must end with {t, 10 + t} at P = 2.
Bins numberedBins(int pes, int tiles) {
  Bins bins(pes, std::vector<std::vector<int>>(tiles));
  for (int p = 0; p < pes; ++p)
    for (int t = 0; t < tiles; ++t) bins[p][t] = {10 * p + t};
  return bins;
}

// What gather returned, one list: the parts' items in order.
std::vector<int> flatten(const std::vector<std::vector<int>>& parts) {
  std::vector<int> all;
  for (const std::vector<int>& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

TEST_CASE("TilePull: every PE's bin of a tile reaches the PE that takes it") {
  test::runWithTimeout(
      [] {
        par::Runtime rt(2, "demand");
        Bins bins = numberedBins(2, 4);
        std::vector<std::vector<int>> gathered(4);
        TilePull<std::vector<int>> pull(rt, "test tile", bins);
        rt.runStage("pull", par::TaskSet::uniform(4), [&](par::Pe& pe, par::TaskId t) {
          gathered[t] = flatten(pull.gather(pe, static_cast<int>(t)));
          std::sort(gathered[t].begin(), gathered[t].end());
        });
        for (int t = 0; t < 4; ++t) CHECK(gathered[t] == std::vector<int>{t, 10 + t});
      },
      20.0, "TilePull gather");
}

TEST_CASE("TilePull: a task failing on one PE ends the stage with its error, not a hang") {
  test::runWithTimeout(
      [] {
        par::Runtime rt(2, "demand");
        Bins bins = numberedBins(2, 2);
        std::string error;
        {
          TilePull<std::vector<int>> pull(rt, "test tile", bins);
          // Task 0 on PE 0 gathers tile 0 and waits for PE 1's reply; task 1 on PE 1 fails
          // without ever answering. A PE answers requests between its tasks or inside gather,
          // so PE 0 sends its request only once PE 1 is inside its task.
          std::atomic<bool> failingTaskStarted{false}, gathering{false};
          try {
            rt.runPinned("pull", par::TaskSet::uniform(2), {0, 1}, [&](par::Pe& pe, par::TaskId t) {
              if (pe.id() == 0) {
                while (!failingTaskStarted.load()) std::this_thread::yield();
                gathering.store(true);
                pull.gather(pe, static_cast<int>(t));
                return;
              }
              failingTaskStarted.store(true);
              while (!gathering.load()) std::this_thread::yield();
              std::this_thread::sleep_for(std::chrono::milliseconds(20));  // PE 0 is waiting by now
              throw std::runtime_error("geometry failed on PE 1");
            });
          } catch (const std::runtime_error& e) {
            error = e.what();
          }
        }
        // The first error, unchanged: what PE 0 threw when it stopped waiting is dropped.
        CHECK(error == "geometry failed on PE 1");
        CHECK(rt.record().error.find("PE 1, task 1: geometry failed on PE 1") != std::string::npos);

        // The runtime is usable again: the next stage (a fresh TilePull) gathers every bin.
        Bins again = numberedBins(2, 2);
        TilePull<std::vector<int>> pull(rt, "test tile again", again);
        std::vector<std::vector<int>> gathered(2);
        rt.runStage("pull again", par::TaskSet::uniform(2), [&](par::Pe& pe, par::TaskId t) {
          gathered[t] = flatten(pull.gather(pe, static_cast<int>(t)));
          std::sort(gathered[t].begin(), gathered[t].end());
        });
        CHECK(gathered[0] == std::vector<int>{0, 10});
        CHECK(gathered[1] == std::vector<int>{1, 11});
        CHECK_FALSE(rt.aborting());
      },
      20.0, "TilePull abort");
}

TEST_CASE("TilePull: the time a PE waits inside its task for a reply is waiting, not busy") {
  test::runWithTimeout(
      [] {
        // PE 0 gathers tile 0 once PE 1 is inside its own 40 ms task; PE 1 answers only after
        // it, so PE 0's task lasts about 40 ms, nearly all of it spent waiting for the reply.
        par::Runtime rt(2, "demand");
        Bins bins = numberedBins(2, 2);
        TilePull<std::vector<int>> pull(rt, "test tile", bins);
        std::atomic<bool> sleeping{false};
        rt.runPinned("pull", par::TaskSet::uniform(2), {0, 1}, [&](par::Pe& pe, par::TaskId) {
          if (pe.id() == 0) {
            while (!sleeping.load()) std::this_thread::yield();
            CHECK(flatten(pull.gather(pe, 0)).size() == 2);
            return;
          }
          sleeping.store(true);
          std::this_thread::sleep_for(std::chrono::milliseconds(40));
        });
        const par::StageRecord& s = rt.record().stages[0];
        const double span0 = [&] {
          for (const par::TaskSpan& span : rt.record().timeline)
            if (span.pe == 0 && span.task == 0) return span.end - span.start;
          return 0.0;
        }();
        CHECK(span0 >= 0.03);
        CHECK(s.pes[0].messageWaitSeconds > 0.5 * span0);
        CHECK(s.pes[0].busySeconds < 0.5 * span0);
        CHECK(s.pes[0].busySeconds + s.pes[0].messageWaitSeconds <= s.wallSeconds + 1e-9);
      },
      20.0, "TilePull wait");
}

}  // namespace
}  // namespace pr::raster
