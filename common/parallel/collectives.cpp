// What the ranks do together between stages: sum values across ranks (sumAcrossRanks), and
// make one run record (gatherRecord). Every rank calls them at the same point (SPMD); each
// wait for another rank is bounded.
//
// One run record from R ranks: every rank measured its own PEs (their busy and idle time,
// messages sent and received, spans, counters); gatherRecord brings those parts to rank 0 and
// sets them in its record, so the record of a run across ranks reads like a record of one
// process with P = R x T PEs.
//
// One clock: each rank's times count from its own runtime's start on its own steady clock.
// Rank 0 estimates every other rank's offset by a few ping-pongs (Cristian's method: the
// answer with the shortest round trip, its time taken as half-way) and moves that rank's
// spans onto its own clock, so the timeline and the Gantt chart line up. Two steady clocks
// differ by a constant offset (bar a drift far below a span's length over a run), so measuring
// it where the ranks meet at the end costs no extra synchronisation at the start.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <thread>

#include "common/parallel/process_group.h"
#include "common/parallel/runtime.h"

namespace pr::par {
namespace {

constexpr int kRecordTag = ProcessGroup::kFirstUserTag + 1;
constexpr int kClockTag = ProcessGroup::kFirstUserTag + 2;
constexpr int kSumTag = ProcessGroup::kFirstUserTag + 3;
constexpr int kShareTag = ProcessGroup::kFirstUserTag + 4;
constexpr int kClockRounds = 8;

// A message with `tag` from rank `from`, waiting at most `seconds` (polling, then sleeping).
Envelope awaitFrom(Transport& transport, int tag, double seconds, const char* what) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (int tries = 0;; ++tries) {
    if (std::optional<Envelope> e = transport.poll(tag)) return std::move(*e);
    if (std::chrono::steady_clock::now() > deadline)
      throw std::runtime_error(std::string("no answer from another rank within the time allowed while waiting for ") + what);
    if (tries < 4096)
      std::this_thread::yield();
    else
      std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

Bytes bytesOf(double v) {
  Bytes b(sizeof v);
  std::memcpy(b.data(), &v, sizeof v);
  return b;
}

double doubleOf(const Envelope& e) {
  if (e.bytes.size() != sizeof(double)) throw std::runtime_error("a clock reading of the wrong size");
  double v;
  std::memcpy(&v, e.bytes.data(), sizeof v);
  return v;
}

// Sets the part of `part` that rank `rank` measured (PEs [first, first + count)) into `into`,
// with its times moved by `offset` seconds onto into's clock.
void mergeRankPart(RunRecord& into, const RunRecord& part, int first, int count, double offset) {
  if (part.stages.size() != into.stages.size())
    throw std::runtime_error("a rank ran " + std::to_string(part.stages.size()) + " stages, rank 0 " +
                             std::to_string(into.stages.size()));
  const auto mine = [&](int pe) { return pe >= first && pe < first + count; };
  for (std::size_t s = 0; s < into.stages.size(); ++s) {
    StageRecord& to = into.stages[s];
    const StageRecord& from = part.stages[s];
    for (int p = first; p < first + count; ++p) to.pes[static_cast<std::size_t>(p)] = from.pes[static_cast<std::size_t>(p)];
    for (const Traffic& t : from.traffic)
      if (mine(t.from)) to.traffic.push_back(t);
    for (const ChannelTraffic& c : from.channels) {
      auto it = std::find_if(to.channels.begin(), to.channels.end(), [&](const ChannelTraffic& x) { return x.name == c.name; });
      if (it == to.channels.end()) {
        to.channels.push_back(c);
      } else {
        it->messages += c.messages;
        it->bytes += c.bytes;
        it->betweenRankMessages += c.betweenRankMessages;
        it->betweenRankBytes += c.betweenRankBytes;
      }
    }
  }
  for (TaskSpan span : part.timeline)
    if (mine(span.pe)) {
      span.start += offset;
      span.end += offset;
      into.timeline.push_back(span);
    }
  for (const CellSpan& cell : part.cells)
    if (mine(cell.pe)) into.cells.push_back(cell);
  // A rank's counters for its own PEs are the ones it measured: whatever rank 0 booked for
  // them (code run on every rank may add a figure for every PE) is replaced, 0 where the rank
  // has no such counter.
  for (CounterRecord& c : into.counters)
    for (int p = first; p < first + count; ++p) c.perPe[static_cast<std::size_t>(p)] = 0.0;
  for (const CounterRecord& c : part.counters) {
    auto it = std::find_if(into.counters.begin(), into.counters.end(), [&](const CounterRecord& x) { return x.name == c.name; });
    if (it == into.counters.end())
      it = into.counters.insert(into.counters.end(), CounterRecord{c.name, std::vector<double>(c.perPe.size(), 0.0)});
    for (int p = first; p < first + count; ++p) it->perPe[static_cast<std::size_t>(p)] = c.perPe[static_cast<std::size_t>(p)];
  }
}

}  // namespace

void Runtime::sumAcrossRanks(std::span<double> values, double timeoutSeconds) {
  PR_CHECK(!inStage_, "sumAcrossRanks is called between stages");
  if (ranks_ == 1) return;
  Transport& transport = *options_.transport;
  const auto asBytes = [&] {
    Bytes b(values.size_bytes());
    if (!values.empty()) std::memcpy(b.data(), values.data(), b.size());
    return b;
  };
  const auto check = [&](const Envelope& e) {
    if (e.bytes.size() != values.size_bytes()) throw std::runtime_error("ranks sum vectors of different lengths");
  };
  if (rank_ != 0) {
    transport.send(0, kSumTag, asBytes());
    const Envelope e = awaitFrom(transport, kSumTag, timeoutSeconds, "rank 0's sums");
    check(e);
    if (!values.empty()) std::memcpy(values.data(), e.bytes.data(), e.bytes.size());
    return;
  }
  // Summed in rank order, so every run adds the same numbers in the same order.
  std::vector<Bytes> parts(static_cast<std::size_t>(ranks_));
  for (int got = 1; got < ranks_; ++got) {
    Envelope e = awaitFrom(transport, kSumTag, timeoutSeconds, "every rank's values to sum");
    check(e);
    parts[static_cast<std::size_t>(e.source)] = std::move(e.bytes);
  }
  for (int r = 1; r < ranks_; ++r)
    for (std::size_t i = 0; i < values.size(); ++i) {
      double v;
      std::memcpy(&v, parts[static_cast<std::size_t>(r)].data() + i * sizeof v, sizeof v);
      values[i] += v;
    }
  for (int r = 1; r < ranks_; ++r) transport.send(r, kSumTag, asBytes());
}

void Runtime::broadcastToRanks(Pe& pe, Bytes& data, double timeoutSeconds) {
  PR_CHECK(inStage_ && pe.id() == firstLocalPe(), "broadcastToRanks runs on each rank's first PE, inside a stage");
  if (ranks_ == 1) return;
  // Booked in this stage, as the data's size (read by the controlling thread only once the
  // stage has ended).
  const auto book = [&](std::size_t bytes) { pendingBroadcasts_.push_back({bytes, 0, PendingBroadcast::To::OtherRanksFirstPe}); };
  Transport& transport = *options_.transport;
  if (rank_ == 0) {
    book(data.size());
    for (int r = 1; r < ranks_; ++r) transport.send(r, kShareTag, r + 1 < ranks_ ? data : std::move(data));
    // Until the data has left: without asynchronous progress it moves only while this rank
    // calls the transport.
    const double t0 = now();
    if (!transport.flush(timeoutSeconds)) throw std::runtime_error("a broadcast did not leave rank 0 within the time allowed");
    pe.recordWait(now() - t0);
    return;
  }
  const double t0 = now();
  data = awaitFrom(transport, kShareTag, timeoutSeconds, "rank 0's broadcast").bytes;
  pe.recordWait(now() - t0);
  book(data.size());
}

const RunRecord& Runtime::gatherRecord(double timeoutSeconds) {
  PR_CHECK(!inStage_, "gatherRecord is called between stages");
  if (ranks_ == 1) return record_;
  Transport& transport = *options_.transport;
  if (rank_ != 0) {
    // The clock: answer rank 0's pings with this rank's time.
    for (int round = 0; round < kClockRounds; ++round) {
      awaitFrom(transport, kClockTag, timeoutSeconds, "rank 0's clock reading");
      transport.send(0, kClockTag, bytesOf(now()));
    }
    const std::string text = toJsonText(record_);
    Bytes b(text.size());
    std::memcpy(b.data(), text.data(), text.size());
    transport.send(0, kRecordTag, std::move(b));
    return record_;
  }
  RunRecord merged = record_;
  std::vector<double> offsets(static_cast<std::size_t>(ranks_), 0.0);
  for (int r = 1; r < ranks_; ++r) {
    double best = std::numeric_limits<double>::infinity();
    for (int round = 0; round < kClockRounds; ++round) {
      const double sent = now();
      transport.send(r, kClockTag, {});
      const double theirs = doubleOf(awaitFrom(transport, kClockTag, timeoutSeconds, "a rank's clock reading"));
      const double back = now();
      if (back - sent < best) {
        best = back - sent;
        offsets[static_cast<std::size_t>(r)] = (sent + back) / 2.0 - theirs;
      }
    }
  }
  for (int got = 1; got < ranks_; ++got) {
    const Envelope e = awaitFrom(transport, kRecordTag, timeoutSeconds, "a rank's run record");
    const RunRecord part = runRecordFromJsonText(std::string(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size()),
                                                 "the run record of rank " + std::to_string(e.source));
    mergeRankPart(merged, part, e.source * localPes_, localPes_, offsets[static_cast<std::size_t>(e.source)]);
  }
  record_ = std::move(merged);
  return record_;
}

}  // namespace pr::par
