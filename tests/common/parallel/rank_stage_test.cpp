// Stages across ranks (rank_stage.cpp), on R ranks inside this process (in_process_ranks.h):
// every task runs once under every strategy, a message-driven stage ends only when chains of
// messages that cross ranks are done, messages between ranks are counted as their encoding on
// both sides, a failure on one rank ends the stage on every rank with its text, and the
// gathered record holds each PE's figures as its own rank measured them.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/parallel/channel.h"
#include "tests/common/parallel/in_process_ranks.h"

using namespace pr::par;
using pr::test::runOnRanks;

TEST_CASE("RankStage: every task runs once, on a PE of the rank that ran it, under every strategy") {
  constexpr int kTasks = 97;
  for (const auto& entry : schedules()) {
    for (const auto& shape : {std::array{2, 1}, std::array{2, 2}, std::array{3, 2}}) {
      const int ranks = shape[0], threads = shape[1];  // CAPTURE cannot take a structured binding
      CAPTURE(entry.name);
      CAPTURE(ranks);
      CAPTURE(threads);
      std::vector<std::atomic<int>> runs(kTasks);
      std::atomic<int> foreign{0};
      std::vector<double> costs(kTasks);
      for (int t = 0; t < kTasks; ++t) costs[static_cast<std::size_t>(t)] = 1.0 + t % 7;
      const auto errors = runOnRanks(ranks, threads, entry.name, [&](Runtime& rt) {
        for (int stage = 0; stage < 3; ++stage)
          rt.runStage("tasks", TaskSet::fromCosts(costs), [&](Pe& pe, TaskId t) {
            runs[static_cast<std::size_t>(t)].fetch_add(1);
            if (!rt.isLocal(pe.id())) foreign.fetch_add(1);
          });
      }, 2);
      for (const std::string& e : errors) CHECK(e == "");
      for (int t = 0; t < kTasks; ++t) CHECK(runs[static_cast<std::size_t>(t)].load() == 3);
      CHECK(foreign.load() == 0);
    }
  }
}

namespace {

struct Hop {
  std::int32_t left;   // hops still to make
  std::int32_t chain;  // which chain, for the sum below
};

}  // namespace

TEST_CASE("RankStage: a stage ends only when chains of messages across ranks are all handled") {
  constexpr int kChains = 24, kLength = 40;
  for (const auto& shape : {std::array{2, 1}, std::array{3, 1}, std::array{4, 2}}) {
    const int ranks = shape[0], threads = shape[1];  // CAPTURE cannot take a structured binding
    CAPTURE(ranks);
    CAPTURE(threads);
    std::atomic<long> handled{0};
    std::vector<long> seenAtEnd(static_cast<std::size_t>(ranks), -1);
    const auto errors = runOnRanks(ranks, threads, "demand", [&](Runtime& rt) {
      const int pes = rt.pes();
      for (int round = 0; round < 2; ++round) {
        // A new channel per round, made in the same order on every rank: round 1's first hops may
        // reach a rank still ending round 0.
        Channel<Hop> hops(rt, "hops", MessageKind::Rays, [&](Pe& pe, Hop&& h) {
          handled.fetch_add(1);
          if (h.chain % 5 == 0) std::this_thread::sleep_for(std::chrono::microseconds(50));
          if (h.left > 0) hops.send(pe, (pe.id() + 1 + h.chain) % pes, Hop{h.left - 1, h.chain});
        });
        rt.runStage("chains", TaskSet::uniform(kChains), [&](Pe& pe, TaskId t) {
          hops.send(pe, (pe.id() + 1) % pes, Hop{kLength, static_cast<std::int32_t>(t)});
        });
        if (round == 0) seenAtEnd[static_cast<std::size_t>(rt.rank())] = handled.load();
      }
    });
    for (const std::string& e : errors) CHECK(e == "");
    // Every rank left round 0 after all of its chains (kLength + 1 messages each) were handled;
    // round 1's could have started on a faster rank, so the figure is at least that.
    for (long seen : seenAtEnd) CHECK(seen >= long(kChains) * (kLength + 1));
    CHECK(handled.load() == 2L * kChains * (kLength + 1));
  }
}

TEST_CASE("RankStage: a message to another rank is counted as its encoding by the sender and the receiver") {
  std::vector<std::vector<int>> drained(4);
  std::vector<RunRecord> records(2);
  const auto errors = runOnRanks(2, 2, "balanced", [&](Runtime& rt) {
    Channel<std::vector<int>> results(rt, "results", MessageKind::Results);
    // PE p sends PE (p + 2) mod 4, on the other rank, p + 1 ints.
    rt.runStage("send", TaskSet::uniform(4), [&](Pe& pe, TaskId) {
      results.send(pe, (pe.id() + 2) % 4, std::vector<int>(static_cast<std::size_t>(pe.id() + 1), pe.id()));
    });
    for (int p = rt.firstLocalPe(); p < rt.firstLocalPe() + rt.localPes(); ++p)
      for (const std::vector<int>& m : results.drain(p)) drained[static_cast<std::size_t>(p)] = m;
    records[static_cast<std::size_t>(rt.rank())] = rt.record();
  });
  for (const std::string& e : errors) CHECK(e == "");
  for (int p = 0; p < 4; ++p) {
    const int sender = (p + 2) % 4;
    CHECK(drained[static_cast<std::size_t>(p)] == std::vector<int>(static_cast<std::size_t>(sender + 1), sender));
    const PeStageRecord& mine = records[static_cast<std::size_t>(p / 2)].stages[0].pes[static_cast<std::size_t>(p)];
    CHECK(mine.messagesSent == 1);
    CHECK(mine.bytesSent == 4u * (p + 1));
    CHECK(mine.messagesReceived == 1);
    CHECK(mine.bytesReceived == 4u * (sender + 1));
  }
}

TEST_CASE("RankStage: a task that fails on one rank ends the stage on every rank with its text") {
  for (const char* schedule : {"demand", "balanced"}) {
    CAPTURE(schedule);
    std::atomic<int> later{0};
    const auto errors = runOnRanks(3, 2, schedule, [&](Runtime& rt) {
      Channel<int> pings(rt, "pings", MessageKind::Requests, [&](Pe&, int&&) {});
      rt.runStage("fine", TaskSet::uniform(12), [&](Pe& pe, TaskId) { pings.send(pe, (pe.id() + 3) % 6, 1); });
      try {
        rt.runStage("breaks", TaskSet::uniform(60), [&](Pe& pe, TaskId t) {
          if (pe.id() == 3 && t >= 0) throw std::runtime_error("task broke");
          pings.send(pe, (pe.id() + 2) % 6, 1);
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        });
      } catch (...) {
        CHECK_THROWS_WITH(rt.runStage("after", TaskSet::uniform(1), [&](Pe&, TaskId) { later.fetch_add(1); }),
                          doctest::Contains("stopped after a failure"));
        throw;
      }
    });
    // The failing rank rethrows the failure unchanged (as on one rank); the others get its
    // record's text, naming stage, PE and task.
    CHECK(errors[1] == "task broke");
    for (int r : {0, 2}) {
      CAPTURE(errors[static_cast<std::size_t>(r)]);
      CHECK(errors[static_cast<std::size_t>(r)].find("stage 'breaks', PE 3, task") != std::string::npos);
      CHECK(errors[static_cast<std::size_t>(r)].find("task broke") != std::string::npos);
    }
    CHECK(later.load() == 0);
  }
}

TEST_CASE("RankStage: the gathered record on rank 0 holds every rank's PEs, their messages and spans") {
  constexpr int kChains = 12, kLength = 9;
  RunRecord merged;
  std::vector<std::uint64_t> tasksOnRank(3, 0);
  const auto errors = runOnRanks(3, 2, "demand", [&](Runtime& rt) {
    Channel<Hop> hops(rt, "hops", MessageKind::Rays, [&](Pe& pe, Hop&& h) {
      if (h.left > 0) hops.send(pe, (pe.id() + 1) % rt.pes(), Hop{h.left - 1, h.chain});
    });
    rt.runStage("chains", TaskSet::uniform(kChains), [&](Pe& pe, TaskId t) {
      hops.send(pe, (pe.id() + 1) % rt.pes(), Hop{kLength, static_cast<std::int32_t>(t)});
    });
    for (int p = rt.firstLocalPe(); p < rt.firstLocalPe() + rt.localPes(); ++p)
      tasksOnRank[static_cast<std::size_t>(rt.rank())] += rt.record().stages[0].pes[static_cast<std::size_t>(p)].tasks;
    // Code run on every rank may book a figure for every PE: a PE's figure in the record is
    // the one its own rank booked.
    for (int p = 0; p < rt.pes(); ++p) rt.addCounter("everywhere", p, double(rt.rank() + 1));
    if (rt.rank() == 1) rt.addCounter("rank 1 only", rt.firstLocalPe(), 5.0);
    RunRecord r = rt.gatherRecord();
    if (rt.rank() == 0) merged = std::move(r);
  });
  for (const std::string& e : errors) CHECK(e == "");
  REQUIRE(merged.stages.size() == 1);
  const StageRecord& s = merged.stages[0];
  REQUIRE(s.pes.size() == 6);
  std::uint64_t tasks = 0, sent = 0, received = 0, handled = 0, trafficMessages = 0;
  for (const PeStageRecord& pe : s.pes) {
    tasks += pe.tasks;
    sent += pe.messagesSent;
    received += pe.messagesReceived;
    handled += pe.messagesHandled;
  }
  for (const Traffic& t : s.traffic) trafficMessages += t.messages;
  // Every hop goes to the next PE: each of the kChains x (kLength + 1) messages is between two PEs.
  const std::uint64_t messages = kChains * (kLength + 1);
  CHECK(tasks == kChains);
  CHECK(tasks == tasksOnRank[0] + tasksOnRank[1] + tasksOnRank[2]);
  CHECK(sent == messages);
  CHECK(received == messages);
  CHECK(handled == messages);
  CHECK(trafficMessages == messages);
  REQUIRE(s.channels.size() == 1);
  CHECK(s.channels[0].messages == messages);
  CHECK(s.channels[0].bytes == messages * sizeof(Hop));
  // Spans of every PE, on rank 0's clock: inside the stage, give or take the clock estimate.
  std::vector<int> spans(6, 0);
  for (const TaskSpan& span : merged.timeline) {
    ++spans[static_cast<std::size_t>(span.pe)];
    CHECK(span.start >= s.startSeconds - 0.05);
    CHECK(span.end <= s.startSeconds + s.wallSeconds + 0.05);
  }
  for (int p = 0; p < 6; ++p) CHECK(spans[static_cast<std::size_t>(p)] > 0);
  const auto counter = [&](const std::string& name) {
    const auto it = std::find_if(merged.counters.begin(), merged.counters.end(), [&](const CounterRecord& c) { return c.name == name; });
    REQUIRE(it != merged.counters.end());
    return it->perPe;
  };
  CHECK(counter("everywhere") == std::vector<double>{1, 1, 2, 2, 3, 3});
  CHECK(counter("rank 1 only") == std::vector<double>{0, 0, 5, 0, 0, 0});
}

TEST_CASE("RankStage: sums across ranks and a computation replicated on each rank's first PE") {
  std::vector<std::vector<double>> sums(3);
  std::vector<std::vector<int>> replicatedOn(3);
  const auto errors = runOnRanks(3, 2, "demand", [&](Runtime& rt) {
    std::vector<double> values(5, 0.0);
    rt.runStage("fill", TaskSet::uniform(5), [&](Pe& pe, TaskId t) { values[static_cast<std::size_t>(t)] = 10.0 * t + pe.id(); });
    std::vector<double> mine(5, 0.0);
    for (int t = 0; t < 5; ++t) mine[static_cast<std::size_t>(t)] = values[static_cast<std::size_t>(t)];
    rt.sumAcrossRanks(mine);
    sums[static_cast<std::size_t>(rt.rank())] = mine;
    std::mutex mutex;
    rt.runOncePerRank("build", [&](Pe& pe) {
      std::lock_guard lock(mutex);
      replicatedOn[static_cast<std::size_t>(rt.rank())].push_back(pe.id());
    });
  });
  for (const std::string& e : errors) CHECK(e == "");
  // Each task ran on one PE of one rank: the sum holds 10 t + that PE on every rank.
  for (int r = 0; r < 3; ++r)
    for (int t = 0; t < 5; ++t) {
      const double v = sums[static_cast<std::size_t>(r)][static_cast<std::size_t>(t)];
      CHECK(v == sums[0][static_cast<std::size_t>(t)]);
      CHECK(v >= 10.0 * t);
      CHECK(v <= 10.0 * t + 5);
    }
  CHECK(replicatedOn[0] == std::vector<int>{0});
  CHECK(replicatedOn[1] == std::vector<int>{2});
  CHECK(replicatedOn[2] == std::vector<int>{4});
}

// Distributed task management across ranks: each rank keeps its own PEs' pools, and a PE that
// runs dry asks the next PE around the ring, on another rank by a steal request that rank
// answers from its pool; nothing goes through rank 0's controller. Rank 0's portions are slow,
// so the other ranks' PEs steal from them.
TEST_CASE("RankStage: distributed task management steals between ranks by messages, every task once") {
  constexpr int kTasks = 60;  // portions of 10 per PE: PEs 0 and 1 (rank 0) hold tasks 0-19
  std::vector<std::atomic<int>> runs(kTasks);
  std::vector<std::atomic<int>> ranOn(kTasks);
  std::uint64_t betweenRanks = 0;
  const auto errors = runOnRanks(3, 2, "distributed", [&](Runtime& rt) {
    rt.runStage("tasks", TaskSet::uniform(kTasks), [&](Pe& pe, TaskId t) {
      runs[static_cast<std::size_t>(t)].fetch_add(1);
      ranOn[static_cast<std::size_t>(t)].store(pe.id());
      if (t < 20) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    });
    const RunRecord& record = rt.gatherRecord();
    if (rt.rank() != 0) return;
    for (const PeStageRecord& pe : record.stages[0].pes) betweenRanks += pe.schedulingMessagesBetweenRanks;
  });
  for (const std::string& e : errors) CHECK(e == "");
  for (int t = 0; t < kTasks; ++t) CHECK(runs[static_cast<std::size_t>(t)].load() == 1);
  int stolenAcross = 0;  // rank 0's tasks that ran on another rank's PE
  for (int t = 0; t < 20; ++t) stolenAcross += ranOn[static_cast<std::size_t>(t)].load() >= 2;
  CHECK(stolenAcross > 0);
  CHECK(betweenRanks > 0);  // steal requests and their answers, two messages each
  CHECK(betweenRanks % 2 == 0);
}

// A task manager across ranks: the controller's pool is on rank 0, each local pool where its PE
// is; a PE on another rank asks rank 0 for refills ahead of need, two messages each (request
// and packet) between ranks, while rank 0's PEs take their packets in place.
TEST_CASE("RankStage: a task manager's local pools on other ranks are refilled from rank 0 by messages, every task once") {
  constexpr int kTasks = 80;
  std::vector<std::atomic<int>> runs(kTasks);
  std::vector<std::uint64_t> between, scheduling;
  std::vector<std::uint64_t> tasksRun;
  const auto errors = runOnRanks(2, 2, "task-manager", [&](Runtime& rt) {
    rt.runStage("tasks", TaskSet::uniform(kTasks), [&](Pe&, TaskId t) {
      runs[static_cast<std::size_t>(t)].fetch_add(1);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
    const RunRecord& record = rt.gatherRecord();
    if (rt.rank() != 0) return;
    for (const PeStageRecord& pe : record.stages[0].pes) {
      between.push_back(pe.schedulingMessagesBetweenRanks);
      scheduling.push_back(pe.schedulingMessages);
      tasksRun.push_back(pe.tasks);
    }
  }, 2);
  for (const std::string& e : errors) CHECK(e == "");
  for (int t = 0; t < kTasks; ++t) CHECK(runs[static_cast<std::size_t>(t)].load() == 1);
  REQUIRE(between.size() == 4);
  for (int p : {0, 1}) CHECK(between[std::size_t(p)] == 0);  // the controller's own rank
  for (int p : {2, 3}) {
    CAPTURE(p);
    // Its first ask finds its pool empty and goes to rank 0 whatever the timing (how many tasks
    // it then gets is timing's). Every packet it ran came as a request and an answer (grain 2),
    // and one more pair told it the pool was spent; all of it crossed between ranks.
    CHECK(between[std::size_t(p)] >= 2);
    CHECK(between[std::size_t(p)] >= 2 * (tasksRun[std::size_t(p)] / 2));
    CHECK(between[std::size_t(p)] % 2 == 0);
    CHECK(scheduling[std::size_t(p)] == between[std::size_t(p)]);
  }
}

// The three ways a broadcast is booked across ranks: to every PE but the root
// (recordBroadcast), carried from rank 0 to each other rank's first PE (broadcastToRanks), and
// from each rank's first PE to the rank's other PEs (recordBroadcastWithinRanks); on one rank
// the last is the first.
TEST_CASE("RankStage: a broadcast is booked to every other PE, to each other rank's first PE, or within each rank") {
  std::vector<std::uint64_t> every, toRanks, within, carried;
  const auto errors = runOnRanks(3, 2, "demand", [&](Runtime& rt) {
    rt.recordBroadcast(100);
    rt.runStage("every", TaskSet::uniform(6), [](Pe&, TaskId) {});
    Bytes data;
    rt.runOncePerRank("share", [&](Pe& pe) {
      if (rt.rank() == 0) data.assign(40, std::byte{7});
      rt.broadcastToRanks(pe, data);
    });
    rt.recordBroadcastWithinRanks(10);
    rt.runStage("within", TaskSet::uniform(6), [](Pe&, TaskId) {});
    const RunRecord& record = rt.gatherRecord();
    if (rt.rank() != 0) return;
    for (int p = 0; p < 6; ++p) {
      every.push_back(record.stages[0].pes[std::size_t(p)].broadcastBytesReceived);
      toRanks.push_back(record.stages[1].pes[std::size_t(p)].broadcastBytesReceived);
      within.push_back(record.stages[2].pes[std::size_t(p)].broadcastBytesReceived);
    }
    carried.push_back(record.stages[1].broadcastBytes);
  });
  for (const std::string& e : errors) CHECK(e == "");
  CHECK(every == std::vector<std::uint64_t>{0, 100, 100, 100, 100, 100});
  CHECK(toRanks == std::vector<std::uint64_t>{0, 0, 40, 0, 40, 0});
  CHECK(within == std::vector<std::uint64_t>{0, 10, 0, 10, 0, 10});
  CHECK(carried == std::vector<std::uint64_t>{40});
  // One rank: within ranks is every PE but PE 0.
  RuntimeOptions options;
  options.pes = 3;
  Runtime one(options);
  one.recordBroadcastWithinRanks(10);
  one.runStage("within", TaskSet::uniform(3), [](Pe&, TaskId) {});
  for (int p = 0; p < 3; ++p) CHECK(one.record().stages[0].pes[std::size_t(p)].broadcastBytesReceived == (p == 0 ? 0u : 10u));
}
