// The thread engine: tasks on P PEs (P above the core count too), errors end the run with the
// error reported, metric invariants (busy <= wall, task counts sum to the pool), broadcasts.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

#include "common/parallel/await_reply.h"
#include "common/parallel/channel.h"
#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "common/parallel/spin_work.h"
#include "common/util/error.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("Runtime: more PEs than cores all take part, each task runs on one PE") {
  Runtime rt(16, "balanced");
  std::vector<std::atomic<int>> ranOn(64);
  for (auto& r : ranOn) r = -1;
  rt.runStage("stage", TaskSet::uniform(64), [&](Pe& pe, TaskId id) {
    CHECK(pe.pes() == 16);
    ranOn[id] = pe.id();
  });
  // Balanced: 4 tasks each, PE p runs 4p..4p+3.
  for (int id = 0; id < 64; ++id) CHECK(ranOn[id] == id / 4);
  const StageRecord& s = rt.record().stages[0];
  for (const PeStageRecord& pe : s.pes) {
    CHECK(pe.tasks == 4);
    CHECK(pe.busySeconds <= s.wallSeconds);
    CHECK(pe.idleSeconds == doctest::Approx(s.wallSeconds - pe.busySeconds));
  }
}

TEST_CASE("Runtime: busy time is measured by the runtime around each task") {
  Runtime rt(2, "balanced");
  rt.runStage("spin", TaskSet::uniform(4), [](Pe&, TaskId) { spinFor(2e-3); });
  const RunRecord& r = rt.record();
  REQUIRE(r.timeline.size() == 4);
  for (const TaskSpan& span : r.timeline) CHECK(span.end - span.start >= 2e-3);
  for (const PeStageRecord& pe : r.stages[0].pes) CHECK(pe.busySeconds >= 4e-3);
  CHECK(r.stages[0].wallSeconds >= 4e-3);
  CHECK(r.stages[0].schedule == "balanced");
}

TEST_CASE("Runtime: an exception in a task ends the stage and is rethrown with its type") {
  for (const ScheduleInfo& info : schedules()) {
    CAPTURE(info.name);
    Runtime rt(4, std::string(info.name));
    std::atomic<int> ran{0};
    pr::test::runWithTimeout(
        [&] {
          CHECK_THROWS_AS(rt.runStage("render", TaskSet::uniform(200),
                                      [&](Pe&, TaskId id) {
                                        ran++;
                                        if (id == 17) throw pr::InputError("bad tile 17");
                                      }),
                          pr::InputError);
        },
        20.0, "Runtime exception run");
    CHECK(rt.record().error.find("bad tile 17") != std::string::npos);
    CHECK(rt.record().error.find("task 17") != std::string::npos);
    CHECK(rt.record().error.find("'render'") != std::string::npos);
  }
}

TEST_CASE("Runtime: a stage after a failed one runs normally") {
  Runtime rt(3);
  CHECK_THROWS_AS(rt.runStage("a", TaskSet::uniform(10), [](Pe&, TaskId) { throw std::runtime_error("x"); }),
                  std::runtime_error);
  std::atomic<int> count{0};
  rt.runStage("b", TaskSet::uniform(10), [&](Pe&, TaskId) { count++; });
  CHECK(count == 10);
}

TEST_CASE("Runtime: bad options are input errors") {
  CHECK_THROWS_AS(Runtime(0), pr::InputError);
  CHECK_THROWS_AS(Runtime(2, "fastest"), pr::InputError);
  ScheduleParams params;
  params.grain = 0;
  CHECK_THROWS_AS(Runtime(2, "demand", params), pr::InputError);
}

TEST_CASE("Runtime: an empty stage and a broadcast are recorded, for every PE but the one that holds the data") {
  Runtime rt(3);
  rt.recordBroadcast(1000);
  rt.recordBroadcast(500, 2);
  rt.runStage("empty", TaskSet{}, [](Pe&, TaskId) {});
  rt.runStage("next", TaskSet::uniform(3), [](Pe&, TaskId) {});
  const RunRecord& r = rt.record();
  REQUIRE(r.stages.size() == 2);
  const std::uint64_t broadcasts[3] = {1, 2, 1}, bytes[3] = {500, 1500, 1000};
  for (int p = 0; p < 3; ++p) {
    const PeStageRecord& pe = r.stages[0].pes[std::size_t(p)];
    CHECK(pe.broadcastsReceived == broadcasts[p]);
    CHECK(pe.broadcastBytesReceived == bytes[p]);
    CHECK(pe.messagesReceived == 0);
  }
  // One PE holds everything: nothing to send.
  Runtime one(1);
  one.recordBroadcast(1000);
  one.runStage("alone", TaskSet::uniform(1), [](Pe&, TaskId) {});
  CHECK(one.record().stages[0].pes[0].broadcastsReceived == 0);
  for (const PeStageRecord& pe : r.stages[1].pes) CHECK(pe.broadcastsReceived == 0);
}

TEST_CASE("Runtime: PE threads live for the run, the same thread serving a PE in every stage") {
  Runtime rt(3, "balanced");
  std::vector<std::vector<std::thread::id>> seen(3);
  std::mutex mutex;
  for (int stage = 0; stage < 4; ++stage)
    rt.runOnEachPe("stage", [&](Pe& pe) {
      std::lock_guard lock(mutex);
      seen[pe.id()].push_back(std::this_thread::get_id());
    });
  std::set<std::thread::id> distinct;
  for (const auto& ids : seen) {
    REQUIRE(ids.size() == 4);
    for (const std::thread::id& id : ids) CHECK(id == ids.front());
    distinct.insert(ids.front());
  }
  CHECK(distinct.size() == 3);
  CHECK(distinct.count(std::this_thread::get_id()) == 0);  // not the controlling thread
}

TEST_CASE("Runtime: runPinned runs task t on PE owner[t] whatever the schedule, and records the owners") {
  Runtime rt(3, "demand");
  const std::vector<int> owner = {2, 0, 2, 1, 0};
  std::vector<std::atomic<int>> ranOn(owner.size());
  rt.runPinned("pinned", TaskSet::uniform(owner.size()), owner, [&](Pe& pe, TaskId t) { ranOn[t] = pe.id(); });
  for (std::size_t t = 0; t < owner.size(); ++t) CHECK(ranOn[t] == owner[t]);
  const StageRecord& s = rt.record().stages[0];
  CHECK(s.schedule == kOwnerPinnedSchedule);
  CHECK(s.owners == owner);
  rt.runStage("free", TaskSet::uniform(2), [](Pe&, TaskId) {});
  CHECK(rt.record().stages[1].schedule == "demand");
  CHECK(rt.record().stages[1].owners.empty());
}

TEST_CASE("Runtime: a PE blocked on an empty mailbox books message waiting, not busy or barrier time") {
  // PE 0's only task sleeps, then sends PE 1 a message; PE 1 has no task and waits for it.
  Runtime rt(2, "demand");
  Channel<int> channel(rt, "late", MessageKind::Data, [](Pe&, int&&) {});
  rt.runPinned("late message", TaskSet::uniform(1), {0}, [&](Pe& pe, TaskId) {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    channel.send(pe, 1, 7);
  });
  const StageRecord& s = rt.record().stages[0];
  const PeStageRecord& waiter = s.pes[1];
  CHECK(waiter.messagesHandled == 1);
  CHECK(waiter.messageWaitSeconds > 0.0);
  CHECK(waiter.busySeconds < waiter.messageWaitSeconds);
  CHECK(waiter.messageWaitSeconds <= s.wallSeconds);
  CHECK(waiter.syncWaitSeconds + waiter.messageWaitSeconds <= s.wallSeconds + 1e-9);
  // The sender only sent: its message wait is zero, its send time is inside its busy time.
  CHECK(s.pes[0].messageWaitSeconds == 0.0);
  CHECK(s.pes[0].sendReceiveSeconds > 0.0);
  CHECK(s.pes[0].sendReceiveSeconds < s.pes[0].busySeconds);
}

TEST_CASE("Runtime: a stage's set-up runs once on each PE before its tasks and handlers there, without a barrier") {
  // PE 1's set-up lasts until PE 0 has run all 8 tasks (and at least 100 ms); every task sends
  // PE 1 a message, which waits until PE 1 is set up. Nothing may run on a PE before its set-up.
  Runtime rt(2, "demand");
  std::atomic<bool> ready[2] = {false, false};
  std::atomic<int> setups{0}, early{0}, handled{0}, tasksRun{0};
  Channel<int> ch(rt, "m", MessageKind::Data, [&](Pe& pe, int&&) {
    if (!ready[pe.id()]) early++;
    handled++;
  });
  pr::test::runWithTimeout(
      [&] {
        rt.runStage(
            "s", TaskSet::uniform(8),
            [&](Pe& pe) {
              if (pe.id() == 1) {
                const auto start = std::chrono::steady_clock::now();
                while (tasksRun < 8 || std::chrono::steady_clock::now() - start < std::chrono::milliseconds(100))
                  std::this_thread::sleep_for(std::chrono::milliseconds(1));
              }
              ready[pe.id()] = true;
              setups++;
            },
            [&](Pe& pe, TaskId) {
              if (!ready[pe.id()]) early++;
              ch.send(pe, 1, 0);
              tasksRun++;
            });
      },
      30.0, "a stage with a set-up");
  CHECK(setups == 2);
  CHECK(early == 0);
  CHECK(handled == 8);
  const RunRecord& r = rt.record();
  int setupSpans = 0;
  for (const TaskSpan& span : r.timeline) setupSpans += span.task == kSetupSpan ? 1 : 0;
  CHECK(setupSpans == 2);
  // PE 0 ran every task while PE 1 was still setting up; the set-up is PE 1's busy time.
  CHECK(r.stages[0].pes[0].tasks == 8);
  CHECK(r.stages[0].pes[1].tasks == 0);
  CHECK(r.stages[0].pes[1].messagesHandled == 8);
  CHECK(r.stages[0].pes[1].busySeconds >= 0.09);
}

TEST_CASE("Runtime: a message a set-up sends after the other PEs are done is still handled") {
  // No tasks at all: PE 0 is done at once, PE 1's set-up then sends it a message. The stage
  // must not end before PE 0 has handled it, nor hang.
  Runtime rt(2, "demand");
  std::atomic<int> handled{0};
  Channel<int> ch(rt, "late", MessageKind::Data, [&](Pe& pe, int&&) {
    CHECK(pe.id() == 0);
    handled++;
  });
  pr::test::runWithTimeout(
      [&] {
        rt.runStage(
            "s", TaskSet::uniform(0),
            [&](Pe& pe) {
              if (pe.id() != 1) return;
              std::this_thread::sleep_for(std::chrono::milliseconds(30));
              ch.send(pe, 0, 1);
            },
            [](Pe&, TaskId) {});
      },
      30.0, "a set-up that sends");
  CHECK(handled == 1);
  CHECK(rt.record().stages[0].pes[0].messagesHandled == 1);
}

TEST_CASE("Runtime: an exception in a set-up ends the stage and names the set-up") {
  Runtime rt(2, "demand");
  CHECK_THROWS_WITH_AS(rt.runStage(
                           "s", TaskSet::uniform(4),
                           [](Pe& pe) {
                             if (pe.id() == 1) throw std::runtime_error("no memory for the BVH");
                           },
                           [](Pe&, TaskId) {}),
                       "no memory for the BVH", std::runtime_error);
  const RunRecord& r = rt.record();
  CHECK(r.error == "stage 's', PE 1, set-up: no memory for the BVH");
  // The failed PE ran no task and its set-up left no span.
  CHECK(r.stages[0].pes[1].tasks == 0);
  for (const TaskSpan& span : r.timeline) CHECK(!(span.pe == 1 && span.task == kSetupSpan));
}

TEST_CASE("Runtime: a task's span carries the time it waited inside, which its busy time leaves out and a replay does not repeat") {
  // PE 0's task waits until PE 1's task, after 40 ms of work begun once PE 0 waits, raises a flag.
  Runtime rt(2, "demand");
  std::atomic<bool> waiting{false}, raised{false};
  rt.runPinned("wait inside", TaskSet::uniform(2), {0, 1}, [&](Pe& pe, TaskId t) {
    if (t == 0) {
      waiting = true;
      waitUntil(pe, "the flag", [&] { return raised.load(); });
    } else {
      while (!waiting) std::this_thread::yield();
      std::this_thread::sleep_for(std::chrono::milliseconds(40));
      raised = true;
    }
  });
  const RunRecord& r = rt.record();
  const auto span = [&](TaskId t) {
    return *std::find_if(r.timeline.begin(), r.timeline.end(), [&](const TaskSpan& s) { return s.task == t; });
  };
  const TaskSpan waiter = span(0), worker = span(1);
  CHECK(waiter.waitSeconds > 0.03);
  CHECK(waiter.waitSeconds <= waiter.end - waiter.start);
  CHECK(worker.waitSeconds == 0.0);
  // Busy is the span less its wait, on the waiting PE.
  CHECK(r.stages[0].pes[0].busySeconds == doctest::Approx(waiter.end - waiter.start - waiter.waitSeconds).epsilon(1e-6));
  // The simulator replays what each task computed: the waiter's few microseconds, the worker's 40 ms.
  const pr::par::Workload w = pr::par::workloadFromRecord(r, "test");
  CHECK(w.stages[0].costs[0] < 0.01);
  CHECK(w.stages[0].costs[1] >= 0.04);
}

TEST_CASE("Runtime: PEs waiting inside tasks on different channels serve each other's requests") {
  // PE 0 asks PE 1 on channel x and waits for the answer; PE 1 asks PE 0 on channel y and
  // waits. Each answer comes from the other's handler, which runs only while that PE waits:
  // serving one channel each, both would wait for ever.
  Runtime rt(2, "demand");
  Channel<int> xAnswers(rt, "x answers", MessageKind::Data), yAnswers(rt, "y answers", MessageKind::Data);
  Channel<int> x(rt, "x", MessageKind::Requests, [&](Pe& pe, int&& v) { xAnswers.send(pe, 0, v + 1); });
  Channel<int> y(rt, "y", MessageKind::Requests, [&](Pe& pe, int&& v) { yAnswers.send(pe, 1, v + 2); });
  std::vector<int> got(2, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  rt.runPinned("ask each other", TaskSet::uniform(2), {0, 1}, [&](Pe& pe, TaskId t) {
    Channel<int>& answers = t == 0 ? xAnswers : yAnswers;
    (t == 0 ? x : y).send(pe, 1 - pe.id(), 10);
    int v = 0;
    waitUntil(pe, "an answer", [&] {
      if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("no answer: a PE served one channel only");
      return answers.tryReceive(pe, v);
    });
    got[pe.id()] = v;
  });
  CHECK(got == std::vector<int>{11, 12});
  CHECK(rt.record().stages[0].pes[0].messagesHandled == 1);
  CHECK(rt.record().stages[0].pes[1].messagesHandled == 1);
}

TEST_CASE("Runtime: a wait that polls a channel books the polls as send/receive time, not also as waiting") {
  // PE 0 polls for a message PE 1 sends after 30 ms: its waiting and its Channel time together
  // fit in its task's span.
  Runtime rt(2, "demand");
  Channel<int> late(rt, "late", MessageKind::Data);
  std::atomic<bool> waiting{false};
  rt.runPinned("poll", TaskSet::uniform(2), {0, 1}, [&](Pe& pe, TaskId t) {
    if (t == 0) {
      waiting = true;
      int v = 0;
      waitUntil(pe, "the late message", [&] { return late.tryReceive(pe, v); });
    } else {
      while (!waiting) std::this_thread::yield();
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
      late.send(pe, 0, 1);
    }
  });
  const RunRecord& r = rt.record();
  const TaskSpan waiter = *std::find_if(r.timeline.begin(), r.timeline.end(), [](const TaskSpan& s) { return s.task == 0; });
  const PeStageRecord& pe0 = r.stages[0].pes[0];
  CHECK(waiter.waitSeconds > 0.0);
  CHECK(pe0.sendReceiveSeconds > 0.0);
  CHECK(waiter.waitSeconds + pe0.sendReceiveSeconds <= (waiter.end - waiter.start) + 1e-6);
}
