// BatchedChannel: items per destination travel as one message per batch — full batches at
// the batch size, partial ones when the sender runs dry — counted as messages of the batch's
// bytes, and a message-driven phase of batches still ends exactly when all work is done.
#include <doctest/doctest.h>

#include <atomic>
#include <vector>

#include "common/parallel/batched_channel.h"

using namespace pr::par;

TEST_CASE("BatchedChannel: full batches at the batch size, the rest when the PE runs dry") {
  Runtime rt(2, "balanced");
  std::atomic<int> items{0}, batches{0}, largest{0};
  BatchedChannel<int> ch(rt, "items", MessageKind::Rays, 4, [&](Pe&, std::vector<int>&& b) {
    items += int(b.size());
    ++batches;
    int seen = largest.load();
    while (int(b.size()) > seen && !largest.compare_exchange_weak(seen, int(b.size()))) {
    }
  });
  // Two tasks, one per PE: PE 0 sends 10 items to PE 1 (batches of 4, 4 and 2), PE 1 none;
  // each batch is counted as its items' encodings (4 bytes each), nothing more.
  rt.runStage("send", TaskSet::uniform(2), [&](Pe& pe, TaskId) {
    if (pe.id() == 0)
      for (int i = 0; i < 10; ++i) ch.send(pe, 1, i);
    flushIfDry(pe, ch);
  });
  CHECK(items == 10);
  CHECK(batches == 3);
  CHECK(largest == 4);
  const StageRecord& s = rt.record().stages[0];
  CHECK(s.pes[0].messagesSent == 3u);
  CHECK(s.pes[0].bytesSent == 10u * sizeof(int));
  CHECK(s.pes[1].messagesReceived == 3u);
}

TEST_CASE("BatchedChannel: a handled batch's storage carries the next batch its receiver sends") {
  // PE 0 sends one full batch to PE 1; in the next stage PE 1 sends one to PE 0, in the
  // storage it received (no allocation on one PE and free on the other per batch).
  Runtime rt(2, "balanced");
  std::vector<const int*> storage(2, nullptr);
  BatchedChannel<int> ch(rt, "items", MessageKind::Rays, 4, [&](Pe& pe, std::vector<int>&& b) {
    CHECK(b.size() == 4u);
    storage[size_t(pe.id())] = b.data();
  });
  for (int sender : {0, 1})
    rt.runStage("send", TaskSet::uniform(2), [&](Pe& pe, TaskId) {
      if (pe.id() == sender)
        for (int i = 0; i < 4; ++i) ch.send(pe, 1 - sender, i);
      flushIfDry(pe, ch);
    });
  REQUIRE(storage[1] != nullptr);
  CHECK(storage[0] == storage[1]);
}

TEST_CASE("BatchedChannel: batch size 1 is one message per item") {
  Runtime rt(2, "balanced");
  std::atomic<int> batches{0};
  BatchedChannel<int> ch(rt, "items", MessageKind::Rays, 1, [&](Pe&, std::vector<int>&& b) {
    CHECK(b.size() == 1u);
    ++batches;
  });
  rt.runStage("send", TaskSet::uniform(2), [&](Pe& pe, TaskId) {
    for (int i = 0; i < 5; ++i) ch.send(pe, 1 - pe.id(), i);
    flushIfDry(pe, ch);
  });
  CHECK(batches == 10);
  CHECK(rt.record().stages[0].pes[0].messagesSent == 5u);
}

TEST_CASE("BatchedChannel: a chain of forwarded items ends the phase only when every item is done") {
  // Each item is a hop count: a PE that receives k > 0 forwards k - 1 to the next PE. Items
  // wait in outboxes between handlers; flushIfDry at the end of each task and handler must
  // send them before the PE can go idle, or the stage would end early (items lost).
  for (int pes : {2, 3, 5}) {
    for (std::size_t batch : {std::size_t{1}, std::size_t{3}, std::size_t{64}}) {
      CAPTURE(pes);
      CAPTURE(batch);
      Runtime rt(pes, "demand");
      std::atomic<long> finished{0}, hops{0};
      BatchedChannel<int>* self = nullptr;
      BatchedChannel<int> ch(rt, "hops", MessageKind::Rays, batch, [&](Pe& pe, std::vector<int>&& b) {
        for (int k : b) {
          ++hops;
          if (k == 0)
            ++finished;
          else
            self->send(pe, (pe.id() + 1) % pe.pes(), k - 1);
        }
        flushIfDry(pe, *self);
      });
      self = &ch;
      constexpr int kTasks = 40, kHops = 7;
      rt.runStage("chains", TaskSet::uniform(kTasks), [&](Pe& pe, TaskId) {
        for (int i = 0; i < 3; ++i) ch.send(pe, (pe.id() + 1) % pe.pes(), kHops);
        flushIfDry(pe, ch);
      });
      CHECK(finished == 3 * kTasks);
      CHECK(hops == 3L * kTasks * (kHops + 1));
      std::uint64_t messages = 0;
      for (const PeStageRecord& r : rt.record().stages[0].pes) messages += r.messagesSent;
      CHECK(messages <= std::uint64_t(hops.load()));
      CHECK(messages * batch >= std::uint64_t(hops.load()));
    }
  }
}
