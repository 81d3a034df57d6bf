// Channel: typed mailboxes between PEs, every message counted at the sender — exact message
// and byte counts per pair for a synthetic exchange with known traffic, and message-driven
// phases (handlers) that end exactly when all work is done.
#include <doctest/doctest.h>

#include <atomic>
#include <numeric>
#include <vector>

#include "common/parallel/channel.h"
#include "common/parallel/metrics.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("Channel: counts are exact for a synthetic all-to-all exchange") {
  const int pes = 4;
  Runtime rt(pes, "balanced");
  Channel<int> results(rt, "results", MessageKind::Data);
  // One task per PE; PE p sends p + 1 messages of 10 * (q + 1) bytes to every other PE q and
  // one message to itself, which is not a transfer between PEs and is not counted.
  rt.runStage("exchange", TaskSet::uniform(pes), [&](Pe& pe, TaskId) {
    for (int q = 0; q < pes; ++q) {
      const int copies = q == pe.id() ? 1 : pe.id() + 1;
      for (int k = 0; k < copies; ++k) results.sendDeclared(pe, q, pe.id() * 100 + k, 10 * (q + 1));
    }
  });
  const StageRecord& s = rt.record().stages[0];
  std::uint64_t sent = 0, received = 0;
  for (int p = 0; p < pes; ++p) {
    const PeStageRecord& r = s.pes[p];
    CHECK(r.messagesSent == 3u * (p + 1));
    std::uint64_t expectBytes = 0, expectIn = 0, expectInBytes = 0;
    for (int q = 0; q < pes; ++q) {
      if (q == p) continue;
      expectBytes += (p + 1) * 10u * (q + 1);
      expectIn += q + 1;
      expectInBytes += (q + 1) * 10u * (p + 1);
    }
    CHECK(r.bytesSent == expectBytes);
    CHECK(r.messagesReceived == expectIn);
    CHECK(r.bytesReceived == expectInBytes);
    sent += r.bytesSent;
    received += r.bytesReceived;
  }
  CHECK(sent == received);
  CHECK(s.traffic.size() == 12);  // every ordered pair of distinct PEs
  for (const Traffic& t : s.traffic) {
    CHECK(t.messages == static_cast<std::uint64_t>(t.from + 1));
    CHECK(t.bytes == t.messages * 10u * (t.to + 1));
  }
  // Every message, including the ones to self, waits in its mailbox in arrival order per sender.
  for (int q = 0; q < pes; ++q) {
    const auto box = results.drain(q);
    CHECK(box.size() == 1u + (6u + 4u) - (q + 1u));  // 1 from self + sum over other senders
  }
}

TEST_CASE("Channel: at P = 1 nothing moves between PEs") {
  Runtime rt(1);
  Channel<double> ch(rt, "self", MessageKind::Data);
  rt.runStage("s", TaskSet::uniform(5), [&](Pe& pe, TaskId) { ch.send(pe, 0, 1.0); });
  CHECK(rt.record().stages[0].pes[0].bytesSent == 0);
  CHECK(rt.record().stages[0].traffic.empty());
  CHECK(ch.drain(0).size() == 5);
}

TEST_CASE("Channel: broadcast is counted once per receiving PE, each copy its encoding") {
  Runtime rt(5, "balanced");
  Channel<std::vector<int>> ch(rt, "map", MessageKind::Data);
  rt.runStage("b", TaskSet::uniform(5), [&](Pe& pe, TaskId id) {
    if (id == 2) ch.broadcast(pe, std::vector<int>(250, 7));
  });
  const StageRecord& s = rt.record().stages[0];
  CHECK(s.pes[2].messagesSent == 4);
  CHECK(s.pes[2].bytesSent == 4000);
  for (int p = 0; p < 5; ++p) CHECK(s.pes[p].bytesReceived == (p == 2 ? 0u : 1000u));
}

TEST_CASE("Channel: a message-driven phase handles every message a handler creates") {
  // A message carries a hop count; its handler forwards it to the next PE until the count is
  // spent. 10 tasks each start a chain of 50 hops: 10 * 51 messages handled in all.
  for (int pes : {1, 3, 8}) {
    CAPTURE(pes);
    Runtime rt(pes, "demand");
    std::atomic<int> handled{0};
    Channel<int> hops(rt, "hops", MessageKind::Data, [&](Pe& pe, int&& left) {
      handled++;
      if (left > 0) hops.send(pe, (pe.id() + 1) % pe.pes(), left - 1);
    });
    pr::test::runWithTimeout(
        [&] { rt.runStage("chains", TaskSet::uniform(10), [&](Pe& pe, TaskId) { hops.send(pe, pe.id(), 50); }); },
        20.0, "message chains");
    CHECK(handled == 510);
    std::uint64_t messagesHandled = 0;
    for (const PeStageRecord& r : rt.record().stages[0].pes) messagesHandled += r.messagesHandled;
    CHECK(messagesHandled == 510);
    // Hops to another PE are counted, hops to oneself are not: at P = 1 none are.
    const RunSummary summary = summarize(rt.record());
    CHECK(summary.total.messages == (pes == 1 ? 0u : 500u));
  }
}

TEST_CASE("Channel: tryReceive takes messages left by an earlier stage") {
  Runtime rt(2, "balanced");
  Channel<int> ch(rt, "mail", MessageKind::Data);
  rt.runStage("send", TaskSet::uniform(2), [&](Pe& pe, TaskId) { ch.send(pe, 1 - pe.id(), pe.id() + 40); });
  std::vector<int> got(2, -1);
  rt.runStage("receive", TaskSet::uniform(2), [&](Pe& pe, TaskId) {
    int v;
    if (ch.tryReceive(pe, v)) got[pe.id()] = v;
  });
  CHECK(got == std::vector<int>{41, 40});
}

TEST_CASE("Channel: the record books each channel's traffic by name and kind, apart from the runtime's own") {
  Runtime rt(3, "balanced");
  Channel<int> rays(rt, "rays", MessageKind::Rays);
  Channel<int> tiles(rt, "tiles", MessageKind::Results);
  Channel<int> idle(rt, "idle", MessageKind::Pixels);
  rt.recordBroadcast(1000);
  // PE p sends 2 rays of 40 bytes to PE (p + 1) mod 3 and one 64-byte tile to PE 0 (PE 0's
  // own tile is no transfer); nothing goes through "idle".
  rt.runOnEachPe("send", [&](Pe& pe) {
    for (int k = 0; k < 2; ++k) rays.sendDeclared(pe, (pe.id() + 1) % 3, k, 40);
    tiles.sendDeclared(pe, 0, pe.id(), 64);
  });
  const StageRecord& s = rt.record().stages[0];
  REQUIRE(s.channels.size() == 2);
  CHECK(s.channels[0].name == "rays");
  CHECK(s.channels[0].kind == "rays");
  CHECK(s.channels[0].messages == 6);
  CHECK(s.channels[0].bytes == 240);
  CHECK(s.channels[1].name == "tiles");
  CHECK(s.channels[1].kind == "results");
  CHECK(s.channels[1].messages == 2);
  CHECK(s.channels[1].bytes == 128);
  const std::vector<KindTraffic> kinds = trafficByKind(s);
  auto find = [&](const char* kind) {
    for (const KindTraffic& k : kinds)
      if (k.kind == kind) return k;
    return KindTraffic{};
  };
  CHECK(find("rays").bytes == 240);
  CHECK(find("results").messages == 2);
  CHECK(find("pixels").messages == 0);
  CHECK(find("broadcasts").messages == 2);  // one copy per receiving PE: PEs 1 and 2 (PE 0 holds it)
  CHECK(find("broadcasts").bytes == 2000);
  // The kinds add up to the stage's measured messages (tasks and broadcasts aside).
  CHECK(find("rays").messages + find("results").messages == summarize(rt.record()).stages[0].messages);
}
