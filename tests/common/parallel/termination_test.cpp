// Termination detection and stress: message trees of unknown size end exactly when the last
// message is handled; random task durations, random exceptions in tasks and handlers, and
// message storms end with the right error and never hang (each run under a timeout guard).
#include <doctest/doctest.h>

#include <atomic>
#include <random>
#include <stdexcept>
#include <string>

#include "common/parallel/channel.h"
#include "common/parallel/spin_work.h"
#include "common/parallel/termination.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("Termination: the counter reports zero once, to the call that reached it") {
  OutstandingWork work;
  work.reset(2);
  work.add();  // a message sent before the task that sent it finishes
  CHECK_FALSE(work.done());
  CHECK_FALSE(work.done());
  CHECK_FALSE(work.finished());
  CHECK(work.done());
  CHECK(work.finished());
}

TEST_CASE("Termination: a binary message tree of unknown size is handled completely") {
  // Each message of depth d > 0 spawns two of depth d - 1 to pseudo-random PEs: a tree of
  // 2^(d+1) - 1 messages per root, the shape of ray or photon spawning.
  for (int round = 0; round < 10; ++round) {
    const int pes = 2 + round % 7;
    Runtime rt(pes, round % 2 ? "distributed" : "demand");
    std::atomic<std::uint64_t> handled{0};
    Channel<std::uint32_t> tree(rt, "tree", MessageKind::Data, [&](Pe& pe, std::uint32_t&& m) {
      handled++;
      const std::uint32_t depth = m & 0xff, salt = m >> 8;
      if (depth == 0) return;
      for (std::uint32_t child = 0; child < 2; ++child) {
        const std::uint32_t s = salt * 2654435761u + child + 1;
        tree.send(pe, static_cast<int>((s >> 16) % pe.pes()), ((s & 0xffff) << 8) | (depth - 1));
      }
    });
    pr::test::runWithTimeout(
        [&] {
          rt.runStage("tree", TaskSet::uniform(4), [&](Pe& pe, TaskId id) {
            tree.send(pe, static_cast<int>(id) % pe.pes(), (static_cast<std::uint32_t>(id) << 8) | 9u);
          });
        },
        20.0, "message tree");
    CHECK(handled == 4u * ((1u << 10) - 1));
  }
}

TEST_CASE("Termination: stress with random durations, exceptions and message storms") {
  std::mt19937 rng(2024);
  for (int round = 0; round < 12; ++round) {
    const int pes = std::uniform_int_distribution<int>(1, 12)(rng);
    const auto& all = schedules();
    const std::string schedule(all[rng() % all.size()].name);
    const int tasks = std::uniform_int_distribution<int>(1, 200)(rng);
    // Either no failure, a failing task, or a failing handler.
    const int mode = round % 3;
    const int failAt = std::uniform_int_distribution<int>(0, tasks - 1)(rng);
    CAPTURE(pes);
    CAPTURE(schedule);
    CAPTURE(mode);
    std::vector<double> durations(tasks);
    for (double& d : durations) d = std::uniform_real_distribution<double>(0.0, 30e-6)(rng);

    Runtime rt(pes, schedule);
    std::atomic<std::uint64_t> handled{0};
    Channel<int> storm(rt, "storm", MessageKind::Data, [&](Pe&, int&& v) {
      handled++;
      if (mode == 2 && v == failAt * 1000 + 7) throw std::logic_error("handler failed on " + std::to_string(v));
    });
    bool threw = false;
    std::string message;
    pr::test::runWithTimeout(
        [&] {
          try {
            rt.runStage("storm", TaskSet::uniform(tasks), [&](Pe& pe, TaskId id) {
              spinFor(durations[id]);
              if (mode == 1 && id == failAt) throw std::runtime_error("task failed on " + std::to_string(id));
              for (int k = 0; k < 20; ++k) storm.send(pe, k % pe.pes(), static_cast<int>(id) * 1000 + k);
            });
          } catch (const std::runtime_error& e) {
            threw = true;
            message = e.what();
          } catch (const std::logic_error& e) {
            threw = true;
            message = e.what();
          }
        },
        30.0, "stress run");
    if (mode == 0) {
      CHECK_FALSE(threw);
      CHECK(handled == static_cast<std::uint64_t>(tasks) * 20);
    } else if (mode == 1) {
      CHECK(threw);
      CHECK(message == "task failed on " + std::to_string(failAt));
      CHECK(rt.record().error.find("task " + std::to_string(failAt)) != std::string::npos);
    } else {
      CHECK(threw);
      CHECK(message == "handler failed on " + std::to_string(failAt * 1000 + 7));
      CHECK(rt.record().error.find("message handler") != std::string::npos);
    }
  }
}
