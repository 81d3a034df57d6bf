// A stage across ranks: the part of the runtime that exists only when the PEs live in more
// than one process (RuntimeOptions::transport with R > 1). Every rank's controlling thread runs
// the same stages (SPMD); during a stage it is its rank's communication thread: it receives
// what other ranks send (data messages for its PEs, the system controller's task answers),
// and takes part in deciding when the stage is over.
//
// When is a stage over? When no PE on any rank has work and no message is in flight. Each rank
// knows only its own part: whether it is passive (OutstandingWork at zero: its PEs have no task
// left, no set-up running and no message waiting to be handled) and how many data messages it
// sent to and received from other ranks in this stage. Rank 0 runs waves (Mattern's
// four-counter method, 1987): it asks every rank for its two counts, which a rank answers only
// while passive; when two consecutive waves find the same totals and sent equals received,
// every message sent had been received by the start of the second wave and every rank was
// passive after receiving it, so no work is left anywhere and none can appear. A passive rank
// becomes active again only by receiving a message, which the second wave would have counted.
//
// Scheduling: a strategy that decides each PE's tasks from reset()'s inputs alone (a static
// portion) runs on every rank for that rank's PEs; so does one with local pools: distributed
// task management, whose PE asks a PE on another rank for half its pool with a steal request,
// answered by that rank's controlling thread, and a task manager, whose PE on another rank than
// 0 asks rank 0 for refills of its local pool ahead of need; any other is held by the system controller on
// rank 0, and a PE on another rank asks it for work with a request message (carrying the
// tasks it finished since it last asked) and waits for the answer, handling its messages.
//
// A failure: the rank whose PE failed tells every other rank, each stops its PEs and rethrows
// the failure's text; the runtime is spent (a later stage throws), and the process group's
// ending (process_group.h) reports it once.
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "common/parallel/process_group.h"
#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"
#include "common/util/error.h"

namespace pr::par {
namespace {

// Every message of the runtime between ranks goes under one tag with this header in front.
constexpr int kRuntimeTag = ProcessGroup::kFirstUserTag;

enum FrameType : std::uint32_t { kData = 1, kProbe, kReply, kEnd, kAbort, kTaskRequest, kTaskAnswer, kStealRequest,
                               kRefillRequest, kRefillAnswer };

struct Frame {
  std::uint32_t type = 0;
  std::int32_t stage = 0;
  std::int32_t from = -1;     // data: the sending PE; task request: the asking PE; probe/reply: the wave
  std::int32_t to = -1;       // data, task answer: the receiving PE
  std::uint32_t channel = 0;  // data: the channel's id
  std::uint32_t reserved = 0;
  std::uint64_t counted = 0;  // data: the bytes the sender booked
};
static_assert(sizeof(Frame) == Runtime::kFrameBytes);

void writeFrame(Bytes& framed, const Frame& f) { std::memcpy(framed.data(), &f, sizeof f); }

// The sent and received totals a rank reports for a wave.
struct WaveCounts {
  std::uint64_t sent = 0, received = 0;
};

// A task answer: the Grab's figures, then its task ids.
struct AnswerHead {
  std::int32_t from, requests, packets, blocking;
  std::uint64_t moved;
};

Bytes encodeAnswer(const Grab& grab) {
  const AnswerHead head{grab.from, grab.requests, grab.packets, grab.blocking ? 1 : 0, grab.moved};
  Bytes answer(sizeof head + grab.tasks.size() * sizeof(TaskId));
  std::memcpy(answer.data(), &head, sizeof head);
  if (!grab.tasks.empty()) std::memcpy(answer.data() + sizeof head, grab.tasks.data(), grab.tasks.size() * sizeof(TaskId));
  return answer;
}

}  // namespace

void Runtime::sendToRank(const ChannelBase& channel, int from, int to, Bytes framed, std::size_t counted) {
  Frame f;
  f.type = kData;
  f.stage = static_cast<std::int32_t>(record_.stages.size());
  f.from = from;
  f.to = to;
  f.channel = channel.id();
  f.counted = counted;
  writeFrame(framed, f);
  // Counted before it can arrive, so the four counters never see it received and not sent.
  rankStage_.sent.fetch_add(1, std::memory_order_acq_rel);
  options_.transport->send(rankOf(to), kRuntimeTag, std::move(framed));
}

void Runtime::sendControl(int to, std::uint32_t type, int stage, int a, Bytes payload) {
  Bytes framed(kFrameBytes + payload.size());
  Frame f;
  f.type = type;
  f.stage = stage;
  f.from = a;
  f.to = a;
  writeFrame(framed, f);
  if (!payload.empty()) std::memcpy(framed.data() + kFrameBytes, payload.data(), payload.size());
  options_.transport->send(to, kRuntimeTag, std::move(framed));
}

// A PE's next tasks: from the strategy here, or, on a rank other than 0 for a strategy the
// controller holds, from rank 0's answer to a request. A PE asks ahead: as soon as an answer
// brings tasks it sends its next request, so the answer travels while those tasks run (a
// local pool of one packet, the seed's latency hiding, 3.3); only its first request, and one
// after an empty pool, is waited for. `asked`: a request of this PE is in flight.
// Waits for the answer to this PE's request (to the controller, or a steal), pumping this
// rank's messages meanwhile; false if the stage is aborting.
bool Runtime::awaitAnswer(Pe& pe, Grab& grab, std::vector<TaskSpan>& spans) {
  std::optional<Grab>& answer = rankStage_.answers[static_cast<std::size_t>(pe.id() - firstLocalPe())];
  int spins = 0;
  for (;;) {
    {
      std::lock_guard lock(rankStage_.answerMutex);
      if (answer) {
        grab = std::move(*answer);
        answer.reset();
        return true;
      }
    }
    if (abort_.load(std::memory_order_acquire)) {
      grab.clear();
      return false;
    }
    // Pump while waiting (the answer may be in this rank's queue already), then block.
    if (handleMessages(pe, spans) || pumpRankStage()) {
      spins = 0;
    } else if (++spins < 4096) {
      std::this_thread::yield();
    } else {
      waitForWork(pe.id());
    }
  }
}

void Runtime::nextTasks(Pe& pe, Scheduler& scheduler, bool askController, Grab& grab, std::vector<TaskSpan>& spans,
                        std::vector<TaskReport>& reports, bool& asked) {
  if (!askController) {
    // A strategy with local pools may stop to ask another rank: a steal from a PE there (asked
    // and waited for), or refills from rank 0 (asked, and waited for only when the pool is
    // empty); then it is asked again. Each ask, and what the search moved before it, is booked
    // here: the answer that ends the search may bring no task, and then the caller books none.
    for (;;) {
      scheduler.next(pe.id(), now(), grab);
      const bool ask = grab.askPe != -1 || grab.refillRequests > 0;
      if (!ask) return;
      bookScheduling(pe.id(), std::uint64_t(grab.requests + grab.packets), grab.transferBytes(), false);
      grab.requests = grab.packets = 0;
      grab.moved = 0;
      for (int i = 0; i < grab.refillRequests; ++i) {
        sendControl(0, kRefillRequest, pe.stage(), pe.id());
        bookScheduling(pe.id(), 1, kTaskRequestBytes, true);  // its answer is booked on arrival
      }
      if (grab.askPe == -1) return;  // tasks to run while the refills travel
      const int victim = grab.askPe;
      if (victim >= 0) {
        Bytes payload(sizeof(std::int32_t));
        const std::int32_t v = victim;
        std::memcpy(payload.data(), &v, sizeof v);
        sendControl(rankOf(victim), kStealRequest, pe.stage(), pe.id(), std::move(payload));
      }
      Grab answer;
      if (!awaitAnswer(pe, answer, spans)) {
        grab.clear();
        return;
      }
      if (victim < 0) continue;  // a refill arrived (refill() has put it in the pool)
      bookScheduling(pe.id(), std::uint64_t(answer.requests + answer.packets), answer.transferBytes(), true);
      scheduler.stolen(pe.id(), victim, std::move(answer.tasks));
    }
  }
  const auto request = [&] {
    Bytes payload(reports.size() * sizeof(TaskReport));
    if (!reports.empty()) std::memcpy(payload.data(), reports.data(), payload.size());
    sendControl(0, kTaskRequest, pe.stage(), pe.id(), std::move(payload));
    reports.clear();
    asked = true;
  };
  if (!asked) request();
  if (!awaitAnswer(pe, grab, spans)) return;
  asked = false;
  if (!grab.tasks.empty()) request();
}

void Runtime::bookScheduling(int pe, std::uint64_t messages, std::uint64_t bytes, bool betweenRanks) {
  if (messages == 0) return;
  PeCounters& c = counters_[static_cast<std::size_t>(pe)];
  c.schedulingMessages.fetch_add(messages, std::memory_order_relaxed);
  c.schedulingBytes.fetch_add(bytes, std::memory_order_relaxed);
  if (!betweenRanks) return;
  c.schedulingMessagesBetweenRanks.fetch_add(messages, std::memory_order_relaxed);
  c.schedulingBytesBetweenRanks.fetch_add(bytes, std::memory_order_relaxed);
}

// One message from another rank, under pumpMutex.
void Runtime::handleRankMessage(Envelope& e) {
  RankStage& rs = rankStage_;
  const int stage = rs.stage;
  if (e.bytes.size() < kFrameBytes) throw std::runtime_error("a runtime message from rank " + std::to_string(e.source) + " is shorter than its header");
  Frame f;
  std::memcpy(&f, e.bytes.data(), sizeof f);
  if (f.stage > stage) {  // a rank already in a later stage: kept until this rank gets there
    rs.early.push_back(std::move(e));
    return;
  }
  if (f.stage < stage) return;  // what a failed stage left behind
  const std::span<const std::byte> payload(e.bytes.data() + kFrameBytes, e.bytes.size() - kFrameBytes);
  switch (f.type) {
    case kData: {
      ChannelBase* channel = f.channel < channelsById_.size() ? channelsById_[f.channel] : nullptr;
      PR_CHECK(channel != nullptr && isLocal(f.to), "a data message for a channel or PE this rank does not have");
      channel->deliver(f.from, f.to, payload, f.counted);
      rs.received.fetch_add(1, std::memory_order_acq_rel);  // after its work was counted
      break;
    }
    case kProbe: rs.probe = f.from; break;
    case kReply:
      if (f.from == rs.wave) {
        WaveCounts c;
        std::memcpy(&c, payload.data(), sizeof c);
        rs.totalSent += c.sent;
        rs.totalReceived += c.received;
        ++rs.replies;
      }
      break;
    case kEnd:
      rs.over.store(true, std::memory_order_release);
      ringAll();
      break;
    case kAbort: {
      std::lock_guard lock(errorMutex_);
      if (!error_) {
        record_.error = std::string(reinterpret_cast<const char*>(payload.data()), payload.size());
        error_ = std::make_exception_ptr(FailedElsewhere(record_.error));
      }
      abort_.store(true, std::memory_order_release);
      ringAll();
      break;
    }
    case kTaskRequest: {
      Scheduler& scheduler = *job_.scheduler;
      for (std::size_t at = 0; at + sizeof(TaskReport) <= payload.size(); at += sizeof(TaskReport)) {
        TaskReport r;
        std::memcpy(&r, payload.data() + at, sizeof r);
        scheduler.finished(f.from, r.task, r.seconds);
      }
      Grab grab;
      scheduler.next(f.from, now(), grab);
      sendControl(rankOf(f.from), kTaskAnswer, stage, f.from, encodeAnswer(grab));
      break;
    }
    case kStealRequest: {  // PE f.from asks for half of local PE victim's pool
      std::int32_t victim = -1;
      if (payload.size() >= sizeof victim) std::memcpy(&victim, payload.data(), sizeof victim);
      PR_CHECK(isLocal(victim), "a steal request for a PE this rank does not have");
      Grab stolen;  // the request and this answer
      stolen.from = victim;
      stolen.requests = stolen.packets = 1;
      stolen.tasks = job_.scheduler->stealFrom(victim);
      stolen.moved = stolen.tasks.size();
      sendControl(rankOf(f.from), kTaskAnswer, stage, f.from, encodeAnswer(stolen));
      break;
    }
    case kRefillRequest: {  // rank 0: a packet of the controller's pool for PE f.from
      const std::vector<TaskId> packet = job_.scheduler->supplyPacket(f.from);
      Bytes answer(packet.size() * sizeof(TaskId));
      if (!packet.empty()) std::memcpy(answer.data(), packet.data(), answer.size());
      sendControl(rankOf(f.from), kRefillAnswer, stage, f.from, std::move(answer));
      break;
    }
    case kRefillAnswer: {  // a packet for local PE f.to's pool; it may be waiting for one
      PR_CHECK(isLocal(f.to), "a refill for a PE this rank does not have");
      std::vector<TaskId> packet(payload.size() / sizeof(TaskId));
      if (!packet.empty()) std::memcpy(packet.data(), payload.data(), packet.size() * sizeof(TaskId));
      bookScheduling(f.to, 1, kTaskPacketHeaderBytes + packet.size() * kTaskEntryBytes, true);
      job_.scheduler->refill(f.to, std::move(packet));
      {
        std::lock_guard lock(rs.answerMutex);
        rs.answers[static_cast<std::size_t>(f.to - firstLocalPe())] = Grab{};
      }
      ring(f.to);
      break;
    }
    case kTaskAnswer: {
      PR_CHECK(isLocal(f.to) && payload.size() >= sizeof(AnswerHead), "a task answer for a PE this rank does not have");
      AnswerHead head;
      std::memcpy(&head, payload.data(), sizeof head);
      Grab grab;
      grab.from = head.from;
      grab.requests = head.requests;
      grab.packets = head.packets;
      grab.blocking = head.blocking != 0;
      grab.moved = head.moved;
      grab.tasks.resize((payload.size() - sizeof head) / sizeof(TaskId));
      if (!grab.tasks.empty()) std::memcpy(grab.tasks.data(), payload.data() + sizeof head, grab.tasks.size() * sizeof(TaskId));
      {
        std::lock_guard lock(rs.answerMutex);
        rs.answers[static_cast<std::size_t>(f.to - firstLocalPe())] = std::move(grab);
      }
      ring(f.to);
      break;
    }
    default: throw std::runtime_error("a runtime message of unknown type " + std::to_string(f.type) + " from rank " + std::to_string(e.source));
  }
}

// Moves this rank's part of the stage along: takes what has arrived, and runs or answers the
// termination waves. Any thread of the rank may call it (the controlling thread in its loop,
// a PE between tasks or while it waits for a task answer); one at a time, the others return
// at once. True when it did something.
bool Runtime::pumpRankStage() {
  RankStage& rs = rankStage_;
  std::unique_lock lock(rs.pumpMutex, std::try_to_lock);
  if (!lock.owns_lock() || !rs.pumping.load(std::memory_order_acquire) || rs.over.load(std::memory_order_acquire))
    return false;
  bool progressed = false;
  while (std::optional<Envelope> e = options_.transport->poll(kRuntimeTag)) {
    handleRankMessage(*e);
    // Decoded (or kept for a later stage, which left nothing here): its storage serves later messages.
    options_.transport->recycle(std::move(e->bytes));
    progressed = true;
  }
  const bool passive = outstanding_.finished();
  if (rank_ == 0) {
    if (!rs.waveOpen && passive) {
      ++rs.wave;
      rs.totalSent = rs.sent.load(std::memory_order_acquire);
      rs.totalReceived = rs.received.load(std::memory_order_acquire);
      rs.replies = 0;
      rs.waveOpen = true;
      for (int r = 1; r < ranks_; ++r) sendControl(r, kProbe, rs.stage, rs.wave);
      progressed = true;
    }
    if (rs.waveOpen && rs.replies == ranks_ - 1) {
      rs.waveOpen = false;
      if (rs.havePrevious && rs.totalSent == rs.totalReceived && rs.totalSent == rs.previousSent &&
          rs.totalReceived == rs.previousReceived) {
        for (int r = 1; r < ranks_; ++r) sendControl(r, kEnd, rs.stage, 0);
        rs.over.store(true, std::memory_order_release);
        ringAll();
      }
      rs.previousSent = rs.totalSent;
      rs.previousReceived = rs.totalReceived;
      rs.havePrevious = true;
      progressed = true;
    }
  } else if (rs.probe >= 0 && passive) {
    const WaveCounts mine{rs.sent.load(std::memory_order_acquire), rs.received.load(std::memory_order_acquire)};
    Bytes payload(sizeof mine);
    std::memcpy(payload.data(), &mine, sizeof mine);
    sendControl(0, kReply, rs.stage, rs.probe, std::move(payload));
    rs.probe = -1;
    progressed = true;
  }
  return progressed;
}

void Runtime::driveRankStage(int stage) {
  RankStage& rs = rankStage_;
  {
    std::lock_guard lock(rs.pumpMutex);
    rs.stage = stage;
    rs.wave = 0;
    rs.probe = -1;
    rs.waveOpen = rs.havePrevious = false;
    rs.replies = 0;
    std::vector<Envelope> early = std::move(rs.early);
    rs.early.clear();
    for (Envelope& e : early) {
      handleRankMessage(e);
      options_.transport->recycle(std::move(e.bytes));
    }
    rs.pumping.store(true, std::memory_order_release);
  }

  int idle = 0;
  while (!rs.over.load(std::memory_order_acquire) && !abort_.load(std::memory_order_acquire)) {
    // Debian's Open MPI moves messages only inside MPI calls (no asynchronous progress), so
    // this thread polls; it backs off to short sleeps when nothing happens, to leave the cores
    // to the PEs, which also pump between their tasks.
    // A send that has not left moves only while this rank calls MPI: no sleeping until it has
    // (eight orbit frames of sort-middle on the hot-spot scene at 2 ranks: 0.22 s
    // with the back-off, 0.16 s without).
    if (pumpRankStage() || options_.transport->sending()) {
      idle = 0;
    } else if (++idle < 64) {
      std::this_thread::yield();
    } else {
      std::this_thread::sleep_for(std::chrono::microseconds(idle < 256 ? 5 : 200));
    }
  }
  {
    std::lock_guard lock(rs.pumpMutex);
    rs.pumping.store(false, std::memory_order_release);
  }

  bool announce = false;
  std::string text;
  {
    std::lock_guard lock(errorMutex_);
    announce = rs.failedHere && !rs.announced;
    rs.announced = rs.announced || announce;
    text = record_.error;
  }
  if (announce) {
    Bytes payload(text.size());
    std::memcpy(payload.data(), text.data(), text.size());
    for (int r = 0; r < ranks_; ++r)
      if (r != rank_) sendControl(r, kAbort, stage, 0, payload);
  }
  if (abort_.load(std::memory_order_acquire)) rs.spent = true;
}

}  // namespace pr::par
