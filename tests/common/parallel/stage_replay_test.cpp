// StageReplay: the rules by which the simulator replays a recorded stage at another P — the
// recorded strategy or the --schedule one, owner-pinned stages split evenly (one task per PE),
// re-dealt round-robin, or excluded with a reason — checked on hand-made stages with exact
// makespans on the zero-cost network.
#include <doctest/doctest.h>

#include "common/parallel/cell_split.h"
#include "common/parallel/simulator.h"
#include "common/parallel/stage_replay.h"
#include "common/util/error.h"

using namespace pr::par;

namespace {

SimStage pinnedStage(const std::string& name, std::vector<double> costs, std::vector<int> owners) {
  SimStage s;
  s.name = name;
  s.tasks = TaskSet::fromCosts(costs);
  s.costs = std::move(costs);
  s.messages.assign(s.costs.size(), 0);
  s.bytes.assign(s.costs.size(), 0);
  s.schedule = std::string(kOwnerPinnedSchedule);
  s.runtimeSchedule = false;
  s.owners = std::move(owners);
  return s;
}

Workload recordedWorkload(std::vector<SimStage> stages, int pes) {
  Workload w;
  w.stages = std::move(stages);
  w.schedule = "demand";
  w.recordedPes = pes;
  return w;
}

// Four tasks of cost 1 under the run's own schedule.
SimStage traceStage(const std::string& schedule) {
  SimStage s;
  s.name = "trace";
  s.tasks = TaskSet::uniform(4);
  s.costs.assign(4, 1.0);
  s.schedule = schedule;
  s.runtimeSchedule = true;
  return s;
}

SimOptions at(int pes) {
  SimOptions options;
  options.pes = pes;
  options.network = networkByName("zero");
  return options;
}

}  // namespace

TEST_CASE("StageReplay: one task per PE splits its total evenly over the new P") {
  // Recorded at P = 2: PE 0 built 1 s of BVHs, PE 1 3 s. At P = 4 each owner gets 4 s / 4.
  const Workload w = recordedWorkload({pinnedStage("build", {1.0, 3.0}, {0, 1})}, 2);
  const Prediction four = predict(w, "", at(4));
  REQUIRE(four.stages.size() == 1);
  CHECK(four.stages[0].rule == "each PE");
  CHECK(four.stages[0].schedule == kOwnerPinnedSchedule);
  CHECK(four.stages[0].note.find("split evenly over 4 owners") != std::string::npos);
  REQUIRE(four.record.stages.size() == 1);
  CHECK(four.record.stages[0].schedule == kOwnerPinnedSchedule);
  CHECK(four.record.stages[0].owners == std::vector<int>{0, 1, 2, 3});
  CHECK(four.record.wallSeconds == doctest::Approx(1.0));
  for (const PeStageRecord& pe : four.record.stages[0].pes) CHECK(pe.busySeconds == doctest::Approx(1.0));
  // At the recorded P the recorded owners and costs stand: the slower PE sets the wall.
  const Prediction two = predict(w, "", at(2));
  CHECK(two.stages[0].rule == "as recorded");
  CHECK(two.record.wallSeconds == doctest::Approx(3.0));
  CHECK(predict(w, "", at(1)).record.wallSeconds == doctest::Approx(4.0));
}

TEST_CASE("StageReplay: regions pinned round-robin are re-dealt round-robin") {
  // Six regions on two PEs, t mod 2. At P = 3: PE 0 has regions 0, 3 (1 + 4 s), PE 1 regions
  // 1, 4 (2 + 5 s), PE 2 regions 2, 5 (3 + 6 s): the makespan is 9 s.
  const Workload w = recordedWorkload({pinnedStage("regions", {1, 2, 3, 4, 5, 6}, {0, 1, 0, 1, 0, 1})}, 2);
  const Prediction p = predict(w, "", at(3));
  CHECK(p.stages[0].rule == "round-robin");
  CHECK(p.record.stages[0].owners == std::vector<int>{0, 1, 2, 0, 1, 2});
  CHECK(p.record.wallSeconds == doctest::Approx(9.0));
  CHECK(p.record.stages[0].pes[0].busySeconds == doctest::Approx(5.0));
}

TEST_CASE("StageReplay: work pinned to one PE stays on that PE at any P") {
  // The world BVH built on the assembler (PE 0): 3 s on PE 0 at P = 2, and at P = 1 and 8.
  const Workload w = recordedWorkload({pinnedStage("build", {3.0}, {0})}, 2);
  for (int pes : {1, 2, 8}) {
    CAPTURE(pes);
    const Prediction p = predict(w, "", at(pes));
    CHECK_FALSE(p.stages[0].excluded);
    CHECK(p.record.wallSeconds == doctest::Approx(3.0));
    CHECK(p.record.stages[0].pes[0].busySeconds == doctest::Approx(3.0));
  }
  CHECK(predict(w, "", at(8)).stages[0].rule == "single owner");
}

TEST_CASE("StageReplay: owners of an undescribed distribution are excluded, with the reason") {
  // Voxels assigned by cost: task 0 on PE 1, tasks 1 and 2 on PE 0. Nothing in the record says
  // how the method would assign them at P = 4.
  const Workload w = recordedWorkload(
      {pinnedStage("voxels", {2.0, 1.0, 1.0}, {1, 0, 0}), pinnedStage("build", {1.0, 1.0}, {0, 1})}, 2);
  const Prediction p = predict(w, "", at(4));
  REQUIRE(p.stages.size() == 2);
  CHECK(p.stages[0].excluded);
  CHECK(p.stages[0].rule == "excluded");
  CHECK(p.stages[0].note.find("not predicted at P = 4") != std::string::npos);
  CHECK_FALSE(p.stages[1].excluded);
  REQUIRE(p.record.stages.size() == 1);  // only the predicted stage
  CHECK(p.record.stages[0].name == "build");
  CHECK(p.record.wallSeconds == doctest::Approx(0.5));
  CHECK(formatStageNotes(p.stages).find("voxels: excluded: owners follow") != std::string::npos);
  // One PE holds all the data: every task runs there.
  const Prediction one = predict(w, "", at(1));
  CHECK(one.stages[0].rule == "one PE");
  CHECK(one.record.wallSeconds == doctest::Approx(4.0 + 2.0));
}

TEST_CASE("StageReplay: --schedule replaces only the run's own schedule, fixed strategies stay") {
  const SimStage traced = traceStage("demand");
  SimStage prePass = traced;
  prePass.name = "cost pre-pass";
  prePass.schedule = "balanced";
  prePass.runtimeSchedule = false;
  const Workload w = recordedWorkload({prePass, traced}, 2);
  const Prediction recorded = predict(w, "", at(2));
  CHECK(recorded.record.stages[0].schedule == "balanced");
  CHECK(recorded.record.stages[1].schedule == "demand");
  CHECK(recorded.stages[1].note == "under the run's schedule");
  const Prediction spiral = predict(w, "spiral", at(2));
  CHECK(spiral.record.stages[0].schedule == "balanced");
  CHECK(spiral.record.stages[1].schedule == "spiral");
  CHECK(spiral.stages[1].note == "under --schedule spiral (recorded: demand)");
  CHECK(spiral.record.schedule == "spiral");
  // A cost table has no recorded schedule: one must be named.
  Workload table = w;
  table.stages[1].schedule.clear();
  CHECK_THROWS_AS(predict(table, "", at(2)), pr::InputError);
}

TEST_CASE("StageReplay: the tasks' preferred PEs are kept at the recorded P and dropped at another") {
  SimStage traced = traceStage("preferred-bias");
  for (TaskInfo& t : traced.tasks.tasks) t.preferredPe = 1;
  const StageReplay same = planReplay(traced, 2, 2, "");
  CHECK(same.stage.tasks.tasks[0].preferredPe == 1);
  CHECK(same.note == "under the run's schedule");
  // At P = 4 the data lies elsewhere: contiguous regions, one task each.
  const StageReplay wider = planReplay(traced, 2, 4, "");
  for (const TaskInfo& t : wider.stage.tasks.tasks) CHECK(t.preferredPe == -1);
  CHECK(wider.note.find("preferred PEs") != std::string::npos);
  const Prediction p = predict(recordedWorkload({traced}, 2), "", at(4));
  CHECK(p.record.wallSeconds == doctest::Approx(1.0));
}

TEST_CASE("StageReplay: handler work stays per PE at the recorded P and is split evenly at another") {
  SimStage s;
  s.handlers = {{3.0, 6, 4, 400}, {1.0, 2, 0, 0}};
  s.schedule = "demand";
  const StageReplay same = planReplay(s, 2, 2, "");
  CHECK(same.handlers[0].seconds == 3.0);
  CHECK(same.handlers[1].spans == 2);
  const StageReplay four = planReplay(s, 2, 4, "");
  REQUIRE(four.handlers.size() == 4);
  for (const HandlerLoad& h : four.handlers) {
    CHECK(h.seconds == doctest::Approx(1.0));
    CHECK(h.spans == 2);
    CHECK(h.messagesSent == 1);
    CHECK(h.bytesSent == 100);
  }
  CHECK(planReplay(SimStage{}, 2, 3, "demand").handlers.size() == 3);  // none recorded: zero on every PE
}

TEST_CASE("StageReplay: set-ups stay per PE at the recorded P and are split evenly at another") {
  SimStage s;
  s.setups = {{3.0, 1, 4, 400}, {1.0, 1, 0, 0}};
  s.schedule = "demand";
  const StageReplay same = planReplay(s, 2, 2, "");
  REQUIRE(same.setups.size() == 2);
  CHECK(same.setups[0].seconds == 3.0);
  CHECK(same.setups[1].seconds == 1.0);
  CHECK(same.note.find("set-ups as recorded") != std::string::npos);
  const StageReplay four = planReplay(s, 2, 4, "");
  CHECK(four.note.find("set-ups: 4 s split evenly over 4 PEs") != std::string::npos);
  REQUIRE(four.setups.size() == 4);
  for (const SetupLoad& load : four.setups) {
    CHECK(load.seconds == doctest::Approx(1.0));
    CHECK(load.messagesSent == 1);
    CHECK(load.bytesSent == 100);
  }
  const StageReplay one = planReplay(s, 2, 1, "");
  REQUIRE(one.setups.size() == 1);
  CHECK(one.setups[0].seconds == doctest::Approx(4.0));
  CHECK(one.setups[0].messagesSent == 0);  // to itself on one PE
  CHECK(planReplay(SimStage{}, 2, 3, "demand").setups.size() == 3);  // none recorded: zero on every PE
}

TEST_CASE("StageReplay: on one PE no data message is charged, the work stays") {
  SimStage s;
  s.name = "trace";
  s.tasks = TaskSet::uniform(2);
  s.costs = {1.0, 1.0};
  s.messages = {2, 0};
  s.bytes = {800, 0};
  s.schedule = "demand";
  s.handlers = {{0.5, 3, 4, 400}, {0.5, 3, 0, 0}};
  const StageReplay one = planReplay(s, 2, 1, "");
  CHECK(one.stage.messages == std::vector<std::uint32_t>{0, 0});
  CHECK(one.stage.bytes == std::vector<std::uint64_t>{0, 0});
  REQUIRE(one.handlers.size() == 1);
  CHECK(one.handlers[0].seconds == doctest::Approx(1.0));
  CHECK(one.handlers[0].messagesSent == 0);
  CHECK(one.note.find("its 6 data messages are to itself on one PE, not charged") != std::string::npos);
  SimOptions options = at(1);
  options.network = NetworkModel{"t", 1.0, 0.0, ""};  // 1 s per message: any charged message shows
  const RunRecord r = simulate(recordedWorkload({s}, 2), "", options);
  CHECK(r.stages[0].pes[0].messagesSent == 0);
  CHECK(r.wallSeconds == doctest::Approx(2 * 2.0 + 3.0));  // 2 tasks, each a request and a packet of 1 s; 3 s of work
  CHECK(planReplay(s, 2, 3, "").stage.messages == std::vector<std::uint32_t>{2, 0});  // kept at P > 1
}

namespace {

// Four screen tiles dealt round-robin, recorded at P = 1: one task of 1 s on PE 0, of which the
// tiles took 0.4, 0.1, 0.1 and 0.1 s (each result 1000 bytes) and 0.3 s was other work.
SimStage tiledStage() {
  SimStage s = pinnedStage("rasterize", {1.0}, {0});
  s.kind = kEachPeStage;
  s.cellSplit = kRoundRobinCells;
  s.cellCollector = 0;
  s.cellCosts = {0.4, 0.1, 0.1, 0.1};
  s.cellBytes = {1000, 1000, 1000, 1000};
  return s;
}

}  // namespace

TEST_CASE("StageReplay: cells dealt round-robin are dealt again at P' from their own costs") {
  const Workload w = recordedWorkload({tiledStage()}, 1);
  // P = 2: PE 0 tiles 0 and 2 (0.5 s), PE 1 tiles 1 and 3 (0.2 s), each 0.15 s of the rest:
  // 0.65 s, where splitting the stage evenly would say 0.5 s.
  const Prediction two = predict(w, "", at(2));
  CHECK(two.stages[0].rule == "cells");
  CHECK(two.stages[0].note.find("4 cells (0.7 s, the largest 0.4 s) dealt round-robin over 2 owners") != std::string::npos);
  CHECK(two.stages[0].note.find("not charged") != std::string::npos);  // no result from another PE in a P = 1 record
  CHECK(two.record.wallSeconds == doctest::Approx(0.65));
  CHECK(two.record.stages[0].pes[1].busySeconds == doctest::Approx(0.35));
  // PE 1's two tiles go to the collector, PE 0 sends nothing.
  CHECK(two.record.stages[0].pes[0].messagesSent == 0);
  CHECK(two.record.stages[0].pes[1].messagesSent == 2);
  CHECK(two.record.stages[0].pes[1].bytesSent == 2000);
  // P = 8: four PEs have a tile each, the slowest 0.4 s; the rest is 0.3 / 8 s per PE.
  const Prediction eight = predict(w, "", at(8));
  CHECK(eight.record.wallSeconds == doctest::Approx(0.4 + 0.3 / 8));
  CHECK(eight.record.stages[0].pes[7].busySeconds == doctest::Approx(0.3 / 8));
}

TEST_CASE("StageReplay: the collector stores other PEs' results at the recorded time per byte") {
  // Recorded at P = 2: tiles 1 and 3 (1000 bytes each) were drawn on PE 1 and stored by PE 0
  // in 0.01 s inside its task and 0.01 s in its handlers: 1e-5 s per byte.
  SimStage s = tiledStage();
  s.owners = {0, 1};
  s.costs = {0.5 + 0.15 + 0.01, 0.2 + 0.15};
  s.tasks = TaskSet::fromCosts(s.costs);
  s.messages = {0, 2};
  s.bytes = {0, 2000};
  s.collectInTaskSeconds = 0.01;
  s.resultsToCollector = 2;
  s.resultBytesToCollector = 2000;
  s.handlers = {{0.01, 2, 0, 0}, {}};
  const Workload w = recordedWorkload({s}, 2);
  // P = 4: one tile per PE; PE 0 stores 3 results, 0.03 s; the rest 0.3 / 4 s each.
  const Prediction four = predict(w, "", at(4));
  CHECK(four.stages[0].rule == "cells");
  CHECK(four.stages[0].note.find("3 results (3000 bytes) to PE 0") != std::string::npos);
  CHECK(four.record.stages[0].pes[0].busySeconds == doctest::Approx(0.4 + 0.075 + 0.03));
  CHECK(four.record.stages[0].pes[0].messagesHandled == 0);  // its handlers' storing is in the cells rule
  // P = 1: every tile on the collector, nothing sent or stored: the tiles and the rest alone.
  const Prediction one = predict(w, "", at(1));
  CHECK(one.record.wallSeconds == doctest::Approx(0.7 + 0.3));
  CHECK(one.record.stages[0].pes[0].messagesSent == 0);
}

TEST_CASE("StageReplay: rows in strips are cut into P' strips of equal height, PEs beyond the rows idle") {
  // Six rows (1, 1, 1, 1, 4, 4 s) recorded on one PE, no collector. P = 2: rows 0-2 (3 s) and
  // 3-5 (9 s); P = 3: 2, 2 and 8 s; P = 8: one row each on PEs 0-5, the slowest 4 s.
  SimStage s = pinnedStage("shade", {12.0}, {0});
  s.kind = kEachPeStage;
  s.cellSplit = kStripCells;
  s.cellCosts = {1, 1, 1, 1, 4, 4};
  s.cellBytes.assign(6, 0);
  const Workload w = recordedWorkload({s}, 1);
  const Prediction two = predict(w, "", at(2));
  CHECK(two.stages[0].rule == "cells");
  CHECK(two.stages[0].note.find("dealt in strips over 2 owners") != std::string::npos);
  CHECK(two.record.wallSeconds == doctest::Approx(9.0));
  CHECK(predict(w, "", at(3)).record.wallSeconds == doctest::Approx(8.0));
  const Prediction eight = predict(w, "", at(8));
  CHECK(eight.record.wallSeconds == doctest::Approx(4.0));
  CHECK(eight.record.stages[0].pes[7].busySeconds == 0.0);
  CHECK(eight.record.stages[0].pes[0].messagesSent == 0);  // no collector: no result sent
}

TEST_CASE("StageReplay: work each PE does in full keeps its recorded mean at any P") {
  // A full-screen buffer cleared on each of 2 PEs (1 s and 3 s): 2 s on every PE at P = 8 and
  // at P = 1, where splitting the total would say 0.5 s and 4 s.
  SimStage s = pinnedStage("clear", {1.0, 3.0}, {0, 1});
  s.kind = kEachPeInFullStage;
  const Workload w = recordedWorkload({s}, 2);
  const Prediction eight = predict(w, "", at(8));
  CHECK(eight.stages[0].rule == "each PE in full");
  CHECK(eight.record.wallSeconds == doctest::Approx(2.0));
  for (const PeStageRecord& pe : eight.record.stages[0].pes) CHECK(pe.busySeconds == doctest::Approx(2.0));
  CHECK(predict(w, "", at(1)).record.wallSeconds == doctest::Approx(2.0));
  CHECK(predict(w, "", at(2)).stages[0].rule == "as recorded");
}

TEST_CASE("StageReplay: at another P a stage's data messages are held at the recorded count, and the note says so") {
  SimStage s = traceStage("demand");
  s.messages = {2, 0, 1, 0};
  s.bytes = {200, 0, 100, 0};
  s.handlers = {{0.5, 3, 1, 50}, {}};
  const StageReplay four = planReplay(s, 2, 4, "");
  CHECK(four.stage.messages == std::vector<std::uint32_t>{2, 0, 1, 0});
  CHECK(four.note.find("its 4 data messages (350 bytes) held at the recorded count") != std::string::npos);
  CHECK(planReplay(s, 2, 2, "").note.find("held") == std::string::npos);  // as recorded
  CHECK(planReplay(s, 2, 1, "").note.find("to itself on one PE") != std::string::npos);
}
