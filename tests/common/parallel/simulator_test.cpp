// Simulator: predictions of recorded thread-engine runs, networks, cost tables, and the
// `parrender simulate` command (table on success, exit status 2 on bad input).
#include <doctest/doctest.h>

#include <algorithm>
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
  for (const char* net : {"zero", "shared-memory", "10gbe", "1gbe", "100mbit"}) {  // switched, slower and slower
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
  // The PE takes its static portion where it is (nothing sent), then task 0 pays 2 * 0.25 +
  // 1000 / 1000 for its messages.
  CHECK(r.wallSeconds == doctest::Approx(1.0 + 1.5 + 1.0));
  CHECK(r.stages[0].pes[0].schedulingMessages == 0);
  CHECK(r.stages[0].pes[0].messagesSent == 2);
  CHECK(r.stages[0].pes[0].bytesSent == 1000);
}

namespace {

// A hand-made record of P = 2: one stage "trace" of `tasks` uniform tasks under `schedule`,
// with the given spans, lasting `wall` seconds.
RunRecord handMadeRecord(const std::string& schedule, std::size_t tasks, std::vector<TaskSpan> timeline, double wall) {
  RunRecord r;
  r.pes = 2;
  r.schedule = schedule;
  StageRecord s;
  s.name = "trace";
  s.schedule = schedule;
  s.tasks = TaskSet::uniform(tasks).tasks;
  s.pes.resize(2);
  s.wallSeconds = wall;
  r.stages.push_back(s);
  r.timeline = std::move(timeline);
  r.wallSeconds = wall;
  return r;
}

// Under "balanced": tasks 0 and 1 of 1 s on PEs 0 and 1, and PE 0 handling one message for 2 s,
// its handler sending one 1000-byte message on.
RunRecord handlerRecord() {
  return handMadeRecord("balanced", 2, {{0, 0, 0, 0.0, 1.0}, {1, 0, 1, 0.0, 1.0}, {0, 0, kMessageSpan, 1.0, 3.0, 1, 1000}},
                        3.0);
}

// Four tasks of 1 s each, in a stage whose PEs first receive 1 MB of replicated data in one message.
pr::par::Workload fourTasksAfterBroadcast() {
  pr::par::Workload w = pr::test::workloadOf(std::vector<double>(4, 1.0));
  w.stages[0].broadcasts = 1;
  w.stages[0].broadcastBytes = 1000000;
  return w;
}

}  // namespace

TEST_CASE("Simulator: message-handler time is charged on its PE with its sends") {
  const Workload w = workloadFromRecord(handlerRecord(), "hand-made");
  REQUIRE(w.stages[0].handlers.size() == 2);
  CHECK(w.stages[0].handlers[0].seconds == doctest::Approx(2.0));
  CHECK(w.stages[0].handlers[0].spans == 1);
  CHECK(w.stages[0].handlers[0].bytesSent == 1000);
  CHECK(w.stages[0].handlers[1].seconds == 0.0);
  SimOptions options;
  options.pes = 2;
  options.network = NetworkModel{"t", 0.25, 1000.0, ""};
  options.recordTimeline = true;
  const RunRecord r = simulate(w, "", options);
  // Each PE takes its static portion (no message), runs its 1 s task; then PE 0 handles its
  // message (2 s) and pays for the one it sends (0.25 s + 1000 / 1000 s).
  CHECK(r.wallSeconds == doctest::Approx(1.0 + 2.0 + 1.25));
  CHECK(r.stages[0].pes[0].busySeconds == doctest::Approx(1.0 + 2.0 + 1.25));
  CHECK(r.stages[0].pes[0].messagesHandled == 1);
  CHECK(r.stages[0].pes[0].messagesSent == 1);
  CHECK(r.stages[0].pes[0].bytesSent == 1000);
  CHECK(r.stages[0].pes[1].busySeconds == doctest::Approx(1.0));
  CHECK(std::count_if(r.timeline.begin(), r.timeline.end(), [](const TaskSpan& t) { return t.task == kMessageSpan; }) ==
        1);
  // At P = 4 the 2 s of handler work and its one message are split over the four owners; the
  // handler busy time summed over PEs is still 2 s plus the send (latency once, 1000 bytes).
  options.pes = 4;
  const RunRecord four = simulate(w, "", options);
  double handlerBusy = 0.0;
  for (int p = 0; p < 4; ++p) handlerBusy += four.stages[0].pes[p].busySeconds - (p < 2 ? 1.0 : 0.0);
  CHECK(handlerBusy == doctest::Approx(2.0 + 0.25 + 1.0));
}

TEST_CASE("Simulator: a PE's set-up is replayed before its first task, per PE at the recorded P, evenly at another") {
  // Recorded at P = 2 under demand: PE 0 set up for 1 s, PE 1 for 3 s (sending one 1000-byte
  // message), then four tasks of 1 s.
  const RunRecord rec = handMadeRecord("demand", 4,
                                       {{0, 0, kSetupSpan, 0.0, 1.0},
                                        {1, 0, kSetupSpan, 0.0, 3.0, 1, 1000},
                                        {0, 0, 0, 1.0, 2.0},
                                        {0, 0, 1, 2.0, 3.0},
                                        {0, 0, 2, 3.0, 4.0},
                                        {1, 0, 3, 3.0, 4.0}},
                                       4.0);
  const Workload w = workloadFromRecord(rec, "hand-made");
  REQUIRE(w.stages[0].setups.size() == 2);
  CHECK(w.stages[0].setups[1].seconds == doctest::Approx(3.0));
  CHECK(w.stages[0].setups[1].bytesSent == 1000);
  CHECK(w.stages[0].setups[1].spans == 1);
  SimOptions options;
  options.pes = 2;
  options.network = networkByName("zero");
  options.recordTimeline = true;
  // PE 0 runs tasks from 1 s while PE 1 still sets up: 4 s, where a barrier after the
  // set-ups would give 3 + 2 = 5 s.
  const RunRecord two = simulate(w, "", options);
  CHECK(two.wallSeconds == doctest::Approx(4.0));
  CHECK(two.stages[0].pes[0].tasks == 3);
  CHECK(two.stages[0].pes[1].busySeconds == doctest::Approx(4.0));
  CHECK(two.stages[0].pes[1].messagesSent == 1);
  CHECK(std::count_if(two.timeline.begin(), two.timeline.end(), [](const TaskSpan& t) { return t.task == kSetupSpan; }) == 2);
  // At P = 4 the 4 s of set-up are 1 s on each PE; at P = 1 all of it comes first.
  options.pes = 4;
  CHECK(simulate(w, "", options).wallSeconds == doctest::Approx(2.0));
  options.pes = 1;
  CHECK(simulate(w, "", options).wallSeconds == doctest::Approx(8.0));
}

TEST_CASE("Simulator: on a shared medium a PE starts a stage when its copy of the broadcast has arrived") {
  // 1 MB of scene from PE 0, which holds it, to each of the 3 other PEs at 1 ms + 1e6 / 12.5e6 s
  // = 81 ms per copy, sent one after another on the one segment: PE p has it at p x 81 ms.
  // PE 3 then runs its 1 s task, its static portion taken where it is.
  const pr::par::Workload w = fourTasksAfterBroadcast();
  SimOptions options;
  options.pes = 4;
  options.network = networkByName("100mbit-shared");
  const RunRecord r = simulate(w, "balanced", options);
  const double copy = 1e-3 + 1e6 / 12.5e6;
  CHECK(r.wallSeconds == doctest::Approx(3 * copy + 1.0));
  CHECK(r.stages[0].pes[3].messageWaitSeconds == doctest::Approx(3 * copy));
  CHECK(r.stages[0].pes[1].messageWaitSeconds == doctest::Approx(copy));
  CHECK(r.stages[0].pes[2].broadcastBytesReceived == 1000000);
  CHECK(r.stages[0].pes[0].broadcastBytesReceived == 0);  // the root
  CHECK(options.network.broadcastArrival(1023, 1024, 1, 1000000) == doctest::Approx(1023 * copy));
  options.network = networkByName("zero");
  CHECK(simulate(w, "balanced", options).wallSeconds == doctest::Approx(1.0));
}

// A switched network broadcasts as MPI does: a short message down a binomial tree (PE p has it
// after bit_width(p) steps, the last of 1024 PEs after log2 1024 = 10), a long one as a scatter
// and an all-gather, whose bytes do not grow with P (2 (P - 1) / P of them).
TEST_CASE("Simulator: on a switched network a broadcast is a binomial tree, or a scatter and an all-gather when long") {
  const NetworkModel& net = networkByName("1gbe");
  const double hop = 50e-6 + 1000.0 / 125e6;  // 1000 bytes, one message
  CHECK(net.broadcastArrival(0, 1024, 1, 1000) == 0.0);  // the root holds it
  CHECK(net.broadcastArrival(1, 1024, 1, 1000) == doctest::Approx(hop));
  CHECK(net.broadcastArrival(2, 1024, 1, 1000) == doctest::Approx(2 * hop));
  CHECK(net.broadcastArrival(3, 1024, 1, 1000) == doctest::Approx(2 * hop));
  CHECK(net.broadcastArrival(1023, 1024, 1, 1000) == doctest::Approx(10 * hop));
  // Under 8 PEs a long message also goes down the tree: 3 PEs, PE 2 after two steps.
  CHECK(net.broadcastArrival(2, 3, 1, 1000000) == doctest::Approx(2 * (50e-6 + 1e6 / 125e6)));
  // 1 MB (long) to 1024 PEs: scatter + ring all-gather, (10 + 1023) latencies and 2 x 1023/1024 MB.
  const double ring = 1033 * 50e-6 + 2.0 * 1023.0 / 1024.0 * 1e6 / 125e6;
  CHECK(net.broadcastArrival(1023, 1024, 1, 1000000) == doctest::Approx(ring));
  CHECK(net.broadcastArrival(1, 1024, 1, 1000000) == doctest::Approx(ring));  // every PE done at the end
  // 100 KB (medium) to 1024 PEs, a power of two: recursive doubling, 2 x 10 latencies; to 1000
  // PEs around the ring, 10 + 999 latencies.
  CHECK(net.broadcastArrival(5, 1024, 1, 100000) ==
        doctest::Approx(20 * 50e-6 + 2.0 * 1023.0 / 1024.0 * 100000 / 125e6));
  CHECK(net.broadcastArrival(5, 1000, 1, 100000) ==
        doctest::Approx(1009 * 50e-6 + 2.0 * 999.0 / 1000.0 * 100000 / 125e6));
  // The thresholds: 12 KiB is no longer short, 512 KiB no longer medium, 8 PEs the first to scatter.
  CHECK(net.broadcastArrival(1023, 1024, 1, 12287) == doctest::Approx(10 * (50e-6 + 12287 / 125e6)));
  CHECK(net.broadcastArrival(1023, 1024, 1, 12288) == doctest::Approx(20 * 50e-6 + 2.0 * 1023.0 / 1024.0 * 12288 / 125e6));
  CHECK(net.broadcastArrival(1, 1024, 1, 524288) == doctest::Approx(1033 * 50e-6 + 2.0 * 1023.0 / 1024.0 * 524288 / 125e6));
  CHECK(net.broadcastArrival(4, 7, 1, 1000000) == doctest::Approx(3 * (50e-6 + 1e6 / 125e6)));
  CHECK(net.broadcastArrival(4, 8, 1, 1000000) == doctest::Approx(10 * 50e-6 + 2.0 * 7.0 / 8.0 * 1e6 / 125e6));
  // The same record replayed: PE 3 of 4 starts after two tree steps, not three copies.
  const pr::par::Workload w = fourTasksAfterBroadcast();
  SimOptions options;
  options.pes = 4;
  options.network = networkByName("100mbit");
  const double step = 1e-3 + 1e6 / 12.5e6;
  const RunRecord r = simulate(w, "balanced", options);
  CHECK(r.stages[0].pes[3].messageWaitSeconds == doctest::Approx(2 * step));
  CHECK(r.wallSeconds == doctest::Approx(2 * step + 1.0));
}

TEST_CASE("Simulator: broadcasts and the time between stages come from the run record") {
  Runtime rt(2, "demand");
  rt.recordBroadcast(5000);
  rt.runStage("first", TaskSet::uniform(2), [](Pe&, TaskId) { spinFor(1e-4); });
  spinFor(2e-3);  // the controlling thread's work between the stages
  rt.runStage("second", TaskSet::uniform(2), [](Pe&, TaskId) { spinFor(1e-4); });
  const Workload w = workloadFromRecord(rt.record(), "test");
  CHECK(w.stages[0].broadcasts == 1);
  CHECK(w.stages[0].broadcastBytes == 5000);
  CHECK(w.stages[1].broadcasts == 0);
  CHECK(w.stages[0].gapBeforeSeconds == 0.0);
  CHECK(w.stages[1].gapBeforeSeconds >= 2e-3);
  CHECK(w.stages[1].gapBeforeSeconds < 1.0);  // generous: a loaded machine may stall the thread
  SimOptions options;
  options.pes = 8;
  const RunRecord r = simulate(w, "", options);  // zero network: the gap is all that is left
  CHECK(r.stages[1].startSeconds == doctest::Approx(r.stages[0].wallSeconds + w.stages[1].gapBeforeSeconds));
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
  CHECK(result.output.find("schedule as recorded per stage (run: demand)") != std::string::npos);
  CHECK(result.output.find("stages at P = 1,2,4,8,16,32,64:\n  spin: scheduled (demand): under the run's schedule") !=
        std::string::npos);
  CHECK(result.output.find("broadcast s") != std::string::npos);

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

TEST_CASE("Simulator: a task that waited 2 ms inside costs its computation only") {
  // Task 0 lasted 3 ms, 2 ms of it waiting for a reply; task 1 computed for 1 ms.
  const RunRecord rec = handMadeRecord("balanced", 2, {{0, 0, 0, 0.0, 0.003, 0, 0, 0.002}, {1, 0, 1, 0.0, 0.001}}, 0.003);
  const Workload w = workloadFromRecord(rec, "hand-made");
  CHECK(w.stages[0].costs[0] == doctest::Approx(0.001));
  CHECK(w.stages[0].costs[1] == doctest::Approx(0.001));
  SimOptions options;
  options.pes = 2;
  options.network = NetworkModel{"free", 0.0, 1e30, ""};
  CHECK(simulate(w, "", options).wallSeconds == doctest::Approx(0.001));
  options.pes = 1;
  CHECK(simulate(w, "", options).wallSeconds == doctest::Approx(0.002));
}

TEST_CASE("Simulator: work recorded on one PE at P = 1 stays serial at P = 2, work recorded on each PE divides") {
  Runtime rt(1, "demand");
  rt.runOnOnePe("build", 0, [](Pe&) { pr::par::spinFor(0.02); });
  rt.runOnEachPe("clear", [](Pe&) { pr::par::spinFor(0.02); });
  const RunRecord& rec = rt.record();
  CHECK(rec.stages[0].kind == kOnePeStage);
  CHECK(rec.stages[1].kind == kEachPeStage);
  const Workload w = workloadFromRecord(runRecordFromJsonText(toJsonText(rec), "round trip"), "test");
  SimOptions options;
  options.pes = 2;
  options.network = NetworkModel{"free", 0.0, 1e30, ""};
  const RunRecord two = simulate(w, "", options);
  // The build: one task of its whole cost on PE 0; the clear: half its cost on each PE.
  CHECK(two.stages[0].pes[0].tasks == 1);
  CHECK(two.stages[0].pes[1].tasks == 0);
  CHECK(two.stages[0].wallSeconds == doctest::Approx(w.stages[0].costs[0]));
  CHECK(two.stages[1].pes[0].tasks == 1);
  CHECK(two.stages[1].pes[1].tasks == 1);
  CHECK(two.stages[1].wallSeconds == doctest::Approx(w.stages[1].costs[0] / 2));
}
