// RunRecord JSON and Chrome trace output: a record survives the round trip through JSON, and
// the trace holds one complete event per task span on the PE's track.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "common/parallel/cell_split.h"
#include "common/parallel/channel.h"
#include "common/parallel/metrics.h"
#include "common/parallel/run_record.h"
#include "common/parallel/simulator.h"
#include "common/util/error.h"

using namespace pr::par;

namespace {

RunRecord sampleRecord() {
  Runtime rt(3, "spiral");
  Channel<int> ch(rt, "c", MessageKind::Data);
  rt.runStage("tiles", TaskSet::grid(3, 2), [&](Pe& pe, TaskId id) { ch.sendDeclared(pe, (pe.id() + 1) % 3, int(id), 24); });
  return rt.record();
}

}  // namespace

TEST_CASE("RunRecord: JSON round trip keeps every measured field") {
  const RunRecord a = sampleRecord();
  const RunRecord b = runRecordFromJsonText(toJsonText(a), "test");
  CHECK(b.pes == 3);
  CHECK(b.schedule == "spiral");
  REQUIRE(b.stages.size() == 1);
  CHECK(b.stages[0].name == "tiles");
  CHECK(b.stages[0].tasks.size() == 6);
  CHECK(b.stages[0].tasks[4].x == a.stages[0].tasks[4].x);
  REQUIRE(b.timeline.size() == a.timeline.size());
  for (std::size_t i = 0; i < a.timeline.size(); ++i) {
    CHECK(b.timeline[i].task == a.timeline[i].task);
    CHECK(b.timeline[i].start == a.timeline[i].start);
    CHECK(b.timeline[i].bytesSent == a.timeline[i].bytesSent);
  }
  for (int p = 0; p < 3; ++p) {
    CHECK(b.stages[0].pes[p].busySeconds == a.stages[0].pes[p].busySeconds);
    CHECK(b.stages[0].pes[p].bytesSent == a.stages[0].pes[p].bytesSent);
    CHECK(b.stages[0].pes[p].messagesReceived == a.stages[0].pes[p].messagesReceived);
  }
  CHECK(b.stages[0].traffic.size() == a.stages[0].traffic.size());
  const auto j = nlohmann::json::parse(toJsonText(a));
  CHECK(j["summary"]["perPe"]["busySeconds"].contains("max"));
  CHECK(j["stages"][0]["summary"].contains("imbalance"));
  CHECK(j["figureProvenance"]["busySeconds"] == "measured");
  CHECK(j["figureProvenance"]["schedulingBytes"].get<std::string>().rfind("modelled", 0) == 0);
  CHECK(j["summary"]["trafficByKind"]["data"]["messages"] == 6);
}

TEST_CASE("RunRecord: JSON round trip keeps the channels, owners and communication times") {
  Runtime rt(2, "demand");
  Channel<int> ch(rt, "pixels", MessageKind::Pixels);
  rt.runPinned("pinned", TaskSet::uniform(3), {1, 0, 1}, [&](Pe& pe, TaskId) { ch.sendDeclared(pe, 1 - pe.id(), 0, 100); });
  const RunRecord a = rt.record();
  const RunRecord b = runRecordFromJsonText(toJsonText(a), "test");
  REQUIRE(b.stages.size() == 1);
  CHECK(b.stages[0].schedule == kOwnerPinnedSchedule);
  CHECK(b.stages[0].owners == std::vector<int>{1, 0, 1});
  REQUIRE(b.stages[0].channels.size() == 1);
  CHECK(b.stages[0].channels[0].name == "pixels");
  CHECK(b.stages[0].channels[0].kind == "pixels");
  CHECK(b.stages[0].channels[0].messages == 3);
  CHECK(b.stages[0].channels[0].bytes == 300);
  for (int p = 0; p < 2; ++p) {
    CHECK(b.stages[0].pes[p].sendReceiveSeconds == a.stages[0].pes[p].sendReceiveSeconds);
    CHECK(b.stages[0].pes[p].messageWaitSeconds == a.stages[0].pes[p].messageWaitSeconds);
  }
  CHECK_THROWS_AS(runRecordFromJsonText(R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"owners":[0,0]}],"timeline":[]})", "bad"),
                  pr::InputError);
}

TEST_CASE("RunRecord: Chrome trace has one complete event per span, in microseconds") {
  const RunRecord r = sampleRecord();
  const auto j = nlohmann::json::parse(toChromeTraceText(r));
  int complete = 0;
  for (const auto& e : j["traceEvents"]) {
    if (e["ph"] != "X") continue;
    ++complete;
    CHECK(e["dur"].get<double>() >= 0.0);
    CHECK(e["tid"].get<int>() < 3);
    CHECK(e["cat"] == "tiles");
  }
  CHECK(complete == static_cast<int>(r.timeline.size()));
}

TEST_CASE("RunRecord: malformed JSON is an input error naming the file and key") {
  CHECK_THROWS_WITH_AS(runRecordFromJsonText("{\"stages\": []}", "m.json"), "m.json: run record has no \"pes\"",
                       pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText("not json", "m.json"), pr::InputError);
  CHECK_THROWS_AS(readRunRecord("/nonexistent/run.json"), pr::InputError);
  CHECK_THROWS_AS(writeRunRecord(sampleRecord(), "/nonexistent/dir/run.json"), pr::InputError);
}

TEST_CASE("RunRecord: a cost profile from a recorded run sums each task's spans") {
  const RunRecord r = sampleRecord();
  const auto costs = taskCostProfile(r, 0);
  REQUIRE(costs.size() == 6);
  for (const TaskSpan& s : r.timeline) CHECK(costs[s.task] == doctest::Approx(s.end - s.start));
}

TEST_CASE("RunRecord: a value of the wrong type deep in the record is an input error") {
  const std::string text =
      "{\"pes\": 1, \"stages\": [{\"name\": \"s\", \"wallSeconds\": 1, \"tasks\": [[1, \"x\", 0]]}], \"timeline\": []}";
  CHECK_THROWS_AS(runRecordFromJsonText(text, "m.json"), pr::InputError);
}

TEST_CASE("RunRecord: a number the field's type cannot hold is an input error, a whole float is read") {
  const auto record = [](const std::string& pes, const std::string& busy, const std::string& span) {
    return "{\"pes\": " + pes + ", \"stages\": [{\"name\": \"s\", \"wallSeconds\": 1, \"pes\": [{\"tasks\": " +
           busy + "}], \"tasks\": [[1, 0, 0]]}], \"timeline\": [" + span + "]}";
  };
  const std::string goodSpan = "[0, 0, 0, 0.0, 1.0, 2, 3]";
  CHECK(runRecordFromJsonText(record("2.0", "5", goodSpan), "m.json").pes == 2);
  CHECK(runRecordFromJsonText(record("1", "5.0", goodSpan), "m.json").stages[0].pes[0].tasks == 5);
  CHECK_THROWS_WITH_AS(runRecordFromJsonText(record("1e300", "5", goodSpan), "m.json"),
                       "m.json: run record \"pes\" must be a whole number in range", pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(record("2.5", "5", goodSpan), "m.json"), pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(record("4294967296", "5", goodSpan), "m.json"), pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(record("1", "-1", goodSpan), "m.json"), pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(record("1", "1e20", goodSpan), "m.json"), pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(record("1", "5", "[0, 0, 0, 0.0, 1.0, 5e9, 3]"), "m.json"), pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(record("1", "5", "[0, 0, 0, 0.0, 1.0, 2, -3]"), "m.json"), pr::InputError);
  // Task -1 is a message handler, -2 a set-up; nothing below.
  CHECK(runRecordFromJsonText(record("1", "5", "[0, 0, -2, 0.0, 1.0, 0, 0]"), "m.json").timeline[0].task == kSetupSpan);
  CHECK_THROWS_AS(runRecordFromJsonText(record("1", "5", "[0, 0, -3, 0.0, 1.0, 0, 0]"), "m.json"), pr::InputError);
}

TEST_CASE("RunRecord: named per-PE counters add up, survive JSON and appear in the summary") {
  Runtime rt(3, "demand");
  rt.runStage("count", TaskSet::grid(6, 1), [&](Pe& pe, TaskId) { rt.addCounter("Test/items", pe.id(), 1.0); });
  rt.addCounter("Test/bytes_held", 2, 4096.0);
  const RunRecord& a = rt.record();
  REQUIRE(a.counters.size() == 2);
  CHECK(a.counters[0].name == "Test/items");
  double items = 0.0;
  for (double v : a.counters[0].perPe) items += v;
  CHECK(items == 6.0);  // one per task, wherever it ran
  CHECK(a.counters[1].perPe == std::vector<double>{0.0, 0.0, 4096.0});

  const RunRecord b = runRecordFromJsonText(toJsonText(a), "test");
  REQUIRE(b.counters.size() == 2);
  CHECK(b.counters[1].name == "Test/bytes_held");
  CHECK(b.counters[1].perPe == a.counters[1].perPe);

  const RunSummary s = summarize(b);
  REQUIRE(s.counters.size() == 2);
  CHECK(s.counters[1].total == 4096.0);
  CHECK(s.counters[1].spread.max == 4096.0);
  CHECK(s.counters[1].spread.min == 0.0);
  CHECK(formatSummary(s).find("Test/bytes_held") != std::string::npos);

  CHECK_THROWS_AS(runRecordFromJsonText(
                      R"({"pes": 2, "stages": [], "timeline": [], "counters": [{"name": "x", "perPe": [1]}]})", "test"),
                  pr::InputError);
}

TEST_CASE("RunRecord: JSON round trip keeps the tasks' preferred PEs, and a record without them has none") {
  Runtime rt(2, "preferred-bias");
  TaskSet tasks = TaskSet::uniform(3);
  tasks.tasks[0].preferredPe = 1;
  tasks.tasks[2].preferredPe = 0;
  rt.runStage("tiles", tasks, [](Pe&, TaskId) {});
  const RunRecord b = runRecordFromJsonText(toJsonText(rt.record()), "test");
  REQUIRE(b.stages.size() == 1);
  REQUIRE(b.stages[0].tasks.size() == 3);
  CHECK(b.stages[0].tasks[0].preferredPe == 1);
  CHECK(b.stages[0].tasks[1].preferredPe == -1);
  CHECK(b.stages[0].tasks[2].preferredPe == 0);
  Runtime plain(2, "demand");
  plain.runStage("tiles", TaskSet::uniform(2), [](Pe&, TaskId) {});
  CHECK(toJsonText(plain.record()).find("preferred") == std::string::npos);
  CHECK_THROWS_AS(runRecordFromJsonText(R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"preferred":[0,1]}],"timeline":[]})", "bad"),
                  pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"preferred":[1]}],"timeline":[]})", "bad"),
                  pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"preferred":[-2]}],"timeline":[]})", "bad"),
                  pr::InputError);
}

TEST_CASE("RunRecord: a span's waiting survives JSON, a record without it reads as none, and a wait longer than its span is refused") {
  RunRecord a;
  a.pes = 1;
  StageRecord s;
  s.name = "s";
  s.tasks = TaskSet::uniform(1).tasks;
  s.pes.resize(1);
  a.stages.push_back(s);
  a.timeline.push_back({0, 0, 0, 0.0, 0.5, 0u, 0u, 0.25});
  CHECK(runRecordFromJsonText(toJsonText(a), "test").timeline[0].waitSeconds == 0.25);
  const std::string head = R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]]}],"timeline":)";
  CHECK(runRecordFromJsonText(head + "[[0,0,0,0,0.5,0,0]]}", "old").timeline[0].waitSeconds == 0.0);
  CHECK_THROWS_AS(runRecordFromJsonText(head + "[[0,0,0,0,0.5,0,0,0.75]]}", "bad"), pr::InputError);
  // A stage's kind is one the runtime writes, or none.
  CHECK_THROWS_AS(
      runRecordFromJsonText(R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"kind":"sideways"}],"timeline":[]})", "bad"),
      pr::InputError);
}

TEST_CASE("RunRecord: a stage's cells come from recordCell, survive JSON, and are refused where the stage has no cell split") {
  Runtime rt(2, "demand");
  rt.runOnEachPe("draw", [&](Pe& pe) {
    for (int tile = pe.id(); tile < 5; tile += 2) rt.recordCell(pe, tile, 0.001 * (tile + 1), 100u * (tile + 1));
    if (pe.id() == 0) rt.recordCell(pe, kCollectCell, 0.002, 0);
  });
  rt.describeCells(kRoundRobinCells, 5, 0);
  const RunRecord a = rt.record();
  CHECK(a.stages[0].cellSplit == kRoundRobinCells);
  CHECK(a.stages[0].cellCollector == 0);
  CHECK(a.stages[0].cellCount == 5);
  REQUIRE(a.cells.size() == 6);
  const RunRecord b = runRecordFromJsonText(toJsonText(a), "test");
  CHECK(b.stages[0].cellSplit == kRoundRobinCells);
  CHECK(b.stages[0].cellCollector == 0);
  CHECK(b.stages[0].cellCount == 5);
  REQUIRE(b.cells.size() == 6);
  for (std::size_t i = 0; i < a.cells.size(); ++i) {
    CHECK(b.cells[i].pe == a.cells[i].pe);
    CHECK(b.cells[i].cell == a.cells[i].cell);
    CHECK(b.cells[i].seconds == a.cells[i].seconds);
    CHECK(b.cells[i].resultBytes == a.cells[i].resultBytes);
  }
  // The simulator reads them as the stage's cells: tiles 1 and 3 were off the collector.
  const Workload w = workloadFromRecord(b, "test");
  CHECK(w.stages[0].cellCosts.size() == 5);
  CHECK(w.stages[0].cellCosts[4] == doctest::Approx(0.005));
  CHECK(w.stages[0].resultsToCollector == 2);
  CHECK(w.stages[0].resultBytesToCollector == 200 + 400);
  CHECK(w.stages[0].collectInTaskSeconds == doctest::Approx(0.002));
  const std::string head = R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]]}],"timeline":[],"cells":)";
  CHECK_THROWS_AS(runRecordFromJsonText(head + "[[0,0,0,0.1,10]]}", "no split"), pr::InputError);
  const std::string split = R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"cellSplit":)";
  CHECK_THROWS_AS(runRecordFromJsonText(split + R"("spiral","cellCount":2,"cellCollector":0}],"timeline":[]})", "bad"), pr::InputError);
  CHECK_THROWS_AS(runRecordFromJsonText(split + R"("strips","cellCount":0,"cellCollector":0}],"timeline":[]})", "bad"), pr::InputError);
  // A cell beyond the stage's count is refused; one within it is read.
  const std::string strips = split + R"("strips","cellCount":2,"cellCollector":-1}],"timeline":[],"cells":)";
  CHECK(runRecordFromJsonText(strips + "[[0,0,1,0.1,0]]}", "good").cells.size() == 1);
  CHECK_THROWS_AS(runRecordFromJsonText(strips + "[[0,0,2,0.1,0]]}", "bad"), pr::InputError);
  // The collector's storing on a stage without a collector would be time nobody is charged.
  CHECK_THROWS_AS(runRecordFromJsonText(strips + "[[0,0,-1,0.1,0]]}", "bad"), pr::InputError);
  // A stage made of cells may have none (nothing drawn): the simulator reads it.
  const RunRecord empty = runRecordFromJsonText(
      R"({"pes":1,"stages":[{"name":"s","wallSeconds":1,"tasks":[[1,0,0]],"owners":[0],"kind":"each PE","cellSplit":"strips","cellCount":2,"cellCollector":-1}],"timeline":[[0,0,0,0,0.5,0,0,0]]})",
      "empty");
  CHECK(workloadFromRecord(empty, "empty").stages[0].cellCosts == std::vector<double>{0.0, 0.0});
}
