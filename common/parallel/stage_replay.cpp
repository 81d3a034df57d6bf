// The replay rules of stage_replay.h: for each recorded stage, the strategy, tasks, owners,
// handler work and set-ups the simulator runs at P'. Pure functions of the recorded stage and P'.
#include "common/parallel/stage_replay.h"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <utility>

#include "common/parallel/cell_split.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/util/error.h"

namespace pr::par {

std::string_view replayRuleName(ReplayRule rule) {
  switch (rule) {
    case ReplayRule::Scheduled: return "scheduled";
    case ReplayRule::AsRecorded: return "as recorded";
    case ReplayRule::Cells: return "cells";
    case ReplayRule::EachPeInFull: return "each PE in full";
    case ReplayRule::EachPe: return "each PE";
    case ReplayRule::RoundRobin: return "round-robin";
    case ReplayRule::SingleOwner: return "single owner";
    case ReplayRule::OnePe: return "one PE";
    case ReplayRule::Excluded: return "excluded";
  }
  return "?";
}

namespace {

// n split into `parts` shares as even as whole numbers allow, the first n mod parts one more.
std::uint64_t evenShare(std::uint64_t n, int parts, int i) {
  return n / parts + (static_cast<std::uint64_t>(i) < n % parts ? 1 : 0);
}

// Recorded per-PE work besides the tasks (handlers, set-ups) at P': per PE as recorded at the
// recorded P, else the total split evenly over the P' PEs.
std::vector<PeLoad> perPeAt(const std::vector<PeLoad>& recorded, int recordedPes, int pes) {
  std::vector<PeLoad> out(static_cast<std::size_t>(pes));
  if (recorded.empty()) return out;
  if (static_cast<int>(recorded.size()) == pes && recordedPes == pes) return recorded;
  PeLoad total;
  for (const PeLoad& h : recorded) {
    total.seconds += h.seconds;
    total.spans += h.spans;
    total.messagesSent += h.messagesSent;
    total.bytesSent += h.bytesSent;
  }
  for (int p = 0; p < pes; ++p)
    out[p] = {total.seconds / pes, evenShare(total.spans, pes, p), evenShare(total.messagesSent, pes, p),
              evenShare(total.bytesSent, pes, p)};
  return out;
}

bool isEachPe(const std::vector<int>& owners, int recordedPes) {
  if (static_cast<int>(owners.size()) != recordedPes) return false;
  for (std::size_t t = 0; t < owners.size(); ++t)
    if (owners[t] != static_cast<int>(t)) return false;
  return true;
}

bool isRoundRobin(const std::vector<int>& owners, int recordedPes) {
  if (static_cast<int>(owners.size()) <= recordedPes) return false;
  for (std::size_t t = 0; t < owners.size(); ++t)
    if (owners[t] != static_cast<int>(t % recordedPes)) return false;
  return true;
}

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g s", s);
  return text;
}

// The data messages and bytes a stage's tasks sent, summed.
std::pair<std::uint64_t, std::uint64_t> taskTraffic(const SimStage& stage) {
  std::uint64_t messages = 0, bytes = 0;
  for (std::uint32_t m : stage.messages) messages += m;
  for (std::uint64_t b : stage.bytes) bytes += b;
  return {messages, bytes};
}

// out as one task per PE at `pes` PEs (PE p's task on PE p), each of `each` seconds, with
// `messages` data messages of `bytes` in all split evenly over them.
void onePerPe(int pes, double each, std::uint64_t messages, std::uint64_t bytes, SimStage& out) {
  const std::size_t n = static_cast<std::size_t>(pes);
  out.tasks = TaskSet::uniform(n);
  out.costs.assign(n, each);
  out.messages.resize(n);
  out.bytes.resize(n);
  out.owners.resize(n);
  for (int p = 0; p < pes; ++p) {
    out.owners[p] = p;
    out.messages[p] = static_cast<std::uint32_t>(evenShare(messages, pes, p));
    out.bytes[p] = evenShare(bytes, pes, p);
  }
}

// The cells rule (stage_replay.h): the recorded cells dealt over `pes` owners by the stage's
// split.
StageReplay cellsAt(const SimStage& stage, int recordedPes, int pes, StageReplay r) {
  r.rule = ReplayRule::Cells;
  const std::size_t cells = stage.cellCosts.size();
  const double total = std::accumulate(stage.costs.begin(), stage.costs.end(), 0.0);
  const double inCells = std::accumulate(stage.cellCosts.begin(), stage.cellCosts.end(), 0.0);
  const double rest = std::max(0.0, total - inCells - stage.collectInTaskSeconds);
  // The collector's storing of results: inside its tasks and in its handlers, per stored byte.
  const int recordedCollector = stage.cellCollector;
  double collectSeconds = stage.collectInTaskSeconds;
  std::vector<PeLoad> handlers = stage.handlers;
  if (recordedCollector >= 0 && static_cast<std::size_t>(recordedCollector) < handlers.size())
    collectSeconds += std::exchange(handlers[recordedCollector], PeLoad{}).seconds;
  const double perByte = stage.resultBytesToCollector > 0 ? collectSeconds / double(stage.resultBytesToCollector) : 0.0;
  r.handlers = perPeAt(handlers, recordedPes, pes);
  const int collector = recordedCollector < 0 ? -1 : recordedCollector < pes ? recordedCollector : 0;

  // The tasks' other messages (not results to the collector) divide among the owners.
  const auto [taskMessages, taskBytes] = taskTraffic(stage);
  const std::uint64_t otherMessages = taskMessages > stage.resultsToCollector ? taskMessages - stage.resultsToCollector : 0;
  const std::uint64_t otherBytes = taskBytes > stage.resultBytesToCollector ? taskBytes - stage.resultBytesToCollector : 0;
  onePerPe(pes, rest / pes, otherMessages, otherBytes, r.stage);
  std::uint64_t results = 0, resultBytes = 0;
  double largest = 0.0;
  for (std::size_t c = 0; c < cells; ++c) {
    const int owner = cellOwner(stage.cellSplit, static_cast<int>(c), static_cast<int>(cells), pes);
    r.stage.costs[owner] += stage.cellCosts[c];
    largest = std::max(largest, stage.cellCosts[c]);
    if (owner != collector && collector >= 0) {
      r.stage.messages[owner] += 1;
      r.stage.bytes[owner] += stage.cellBytes[c];
      results += 1;
      resultBytes += stage.cellBytes[c];
    }
  }
  if (collector >= 0) r.stage.costs[collector] += perByte * double(resultBytes);
  r.note = std::to_string(cells) + " cells (" + seconds(inCells) + ", the largest " + seconds(largest) + ") dealt " +
           (stage.cellSplit == kStripCells ? std::string("in strips") : stage.cellSplit) + " over " + std::to_string(pes) +
           " owners; " + seconds(rest) +
           " of other per-PE work split evenly (assumes it divides evenly)";
  if (collector >= 0 && results == 0) r.note += "; every cell on the collector, PE " + std::to_string(collector) + ": no result sent";
  if (collector >= 0 && results > 0) {
    r.note += "; " + std::to_string(results) + " results (" + std::to_string(resultBytes) + " bytes) to PE " +
              std::to_string(collector);
    r.note += stage.resultBytesToCollector > 0 ? ", stored at the record's " + seconds(perByte * 1e6) + " per MB"
                                       : ", their storing not charged (the record has no result from another PE to time it by)";
  }
  return r;
}

}  // namespace

namespace {

StageReplay planRule(const SimStage& stage, int recordedPes, int pes, std::string_view schedule) {
  StageReplay r;
  r.stage = stage;
  r.handlers = perPeAt(stage.handlers, recordedPes, pes);
  r.setups = perPeAt(stage.setups, recordedPes, pes);
  const bool pinned = stage.schedule == kOwnerPinnedSchedule;
  if (!pinned) {
    r.rule = ReplayRule::Scheduled;
    r.runtimeSchedule = stage.runtimeSchedule || stage.schedule.empty();
    r.schedule = r.runtimeSchedule && !schedule.empty() ? std::string(schedule) : stage.schedule;
    if (r.schedule.empty()) throw InputError("stage '" + stage.name + "' has no schedule: name one with --schedule");
    r.note = r.runtimeSchedule ? (stage.schedule.empty() || r.schedule == stage.schedule
                                      ? "under the run's schedule"
                                      : "under --schedule " + r.schedule + " (recorded: " + stage.schedule + ")")
                               : "under its own recorded schedule";
    r.stage.owners.clear();
    // A task's preferred PE names the PE holding its data in the recorded split; at another P
    // the data lies elsewhere, so the regions fall back to contiguous portions. (A cost table,
    // recordedPes = 0, keeps the preferences it was given.)
    if (recordedPes > 0 && pes != recordedPes) {
      bool dropped = false;
      for (TaskInfo& t : r.stage.tasks.tasks) {
        dropped = dropped || t.preferredPe >= 0;
        t.preferredPe = -1;
      }
      if (dropped) r.note += " (the tasks' preferred PEs are the recorded split's: dropped)";
    }
    return r;
  }

  r.schedule = std::string(kOwnerPinnedSchedule);
  const std::vector<int>& owners = stage.owners;
  const std::size_t n = stage.costs.size();
  if (owners.size() != n) {
    r.rule = ReplayRule::Excluded;
    r.schedule.clear();
    r.note = "owner-pinned, but the record holds no owners for its tasks";
    return r;
  }
  if (pes == recordedPes) {
    r.rule = ReplayRule::AsRecorded;
    r.note = "owners as recorded";
    return r;
  }
  if (!stage.cellSplit.empty() && stage.kind == kEachPeStage && isEachPe(owners, recordedPes))
    return cellsAt(stage, recordedPes, pes, std::move(r));
  if (stage.kind == kEachPeInFullStage && isEachPe(owners, recordedPes)) {
    // Every PE does the work whole at any P: P' tasks of the recorded mean.
    r.rule = ReplayRule::EachPeInFull;
    const double mean = std::accumulate(stage.costs.begin(), stage.costs.end(), 0.0) / double(std::max<std::size_t>(n, 1));
    const auto [messages, bytes] = taskTraffic(stage);  // any it sent: held at the recorded count
    onePerPe(pes, mean, messages, bytes, r.stage);
    r.note = "one task per PE, each doing the work in full: the recorded mean, " + seconds(mean) + ", on each of " +
             std::to_string(pes) + " PEs (an upper bound where the work shrinks with the PE's share)";
    return r;
  }
  if (stage.kind == kOnePeStage && n > 0) {
    // Work done once whatever P (on each rank side by side, for a stage run once per rank):
    // one task, the longest copy, on the recorded PE when the new P has it, else on PE 0.
    r.rule = ReplayRule::SingleOwner;
    const std::size_t longest = std::size_t(std::max_element(stage.costs.begin(), stage.costs.end()) - stage.costs.begin());
    const int owner = owners[longest] < pes ? owners[longest] : 0;
    r.stage.tasks.tasks = {stage.tasks.tasks[longest]};
    r.stage.costs = {stage.costs[longest]};
    r.stage.messages = stage.messages.empty() ? std::vector<std::uint32_t>{} : std::vector<std::uint32_t>{stage.messages[longest]};
    r.stage.bytes = stage.bytes.empty() ? std::vector<std::uint64_t>{} : std::vector<std::uint64_t>{stage.bytes[longest]};
    r.stage.owners = {owner};
    r.note = "work done once (recorded as one-PE work): " + seconds(stage.costs[longest]) + " on PE " + std::to_string(owner) +
             " at any P";
    return r;
  }
  if (isEachPe(owners, recordedPes)) {
    // P' tasks of total/P' each: the method's split of its data at P' is assumed even.
    r.rule = ReplayRule::EachPe;
    const double total = std::accumulate(stage.costs.begin(), stage.costs.end(), 0.0);
    const auto [messages, bytes] = taskTraffic(stage);
    onePerPe(pes, total / pes, messages, bytes, r.stage);
    r.note = "one task per PE: " + seconds(total) + " of work split evenly over " + std::to_string(pes) +
             " owners (assumes the data divides evenly)";
    return r;
  }
  if (isRoundRobin(owners, recordedPes)) {
    r.rule = ReplayRule::RoundRobin;
    for (std::size_t t = 0; t < n; ++t) r.stage.owners[t] = static_cast<int>(t % pes);
    r.note = std::to_string(n) + " tasks re-dealt round-robin over " + std::to_string(pes) +
             " owners (assumes the regions do not depend on P" +
             (recordedPes == 1 ? "; a P = 1 record cannot tell round-robin from another split)" : ")");
    return r;
  }
  if (n > 0 && owners[0] < pes && std::all_of(owners.begin(), owners.end(), [&](int o) { return o == owners[0]; })) {
    r.rule = ReplayRule::SingleOwner;
    r.note = "every task on PE " + std::to_string(owners[0]) + " at any P (work done once, by one PE)";
    return r;
  }
  if (pes == 1) {
    r.rule = ReplayRule::OnePe;
    r.stage.owners.assign(n, 0);
    r.note = "every task on the one PE";
    return r;
  }
  r.rule = ReplayRule::Excluded;
  r.schedule.clear();
  r.note = "owners follow a data distribution the record does not describe (neither one task per PE nor "
           "round-robin): not predicted at P = " +
           std::to_string(pes);
  return r;
}

}  // namespace

StageReplay planReplay(const SimStage& stage, int recordedPes, int pes, std::string_view schedule) {
  StageReplay r = planRule(stage, recordedPes, pes, schedule);
  if (!stage.setups.empty() && r.rule != ReplayRule::Excluded) {
    double total = 0.0;
    for (const SetupLoad& load : stage.setups) total += load.seconds;
    r.note += pes == recordedPes && static_cast<int>(stage.setups.size()) == pes ? "; set-ups as recorded"
                                 : "; set-ups: " + seconds(total) + " split evenly over " + std::to_string(pes) +
                                       " PEs (assumes the data divides evenly)";
  }
  if (pes > 1 && recordedPes > 1 && pes != recordedPes && r.rule != ReplayRule::Cells && r.rule != ReplayRule::Excluded) {
    // How many messages a partitioned method sends follows its split at P', which the record
    // does not hold at a grain fine enough to make again: the count stays the recorded one.
    auto [messages, bytes] = taskTraffic(r.stage);
    for (const std::vector<PeLoad>* loads : {&r.handlers, &r.setups})
      for (const PeLoad& load : *loads) messages += load.messagesSent, bytes += load.bytesSent;
    if (messages > 0)
      r.note += "; its " + std::to_string(messages) + " data messages (" + std::to_string(bytes) +
                " bytes) held at the recorded count (the split that makes them is not recorded finely enough to make again at P = " +
                std::to_string(pes) + ")";
  }
  if (pes != 1 || recordedPes <= 1) return r;  // a cost table (0) says what its tasks send
  // On one PE every message would be to itself, which is no transfer (Runtime::countMessage):
  // the work stays, the data traffic goes.
  std::uint64_t dropped = 0;
  for (std::uint32_t& m : r.stage.messages) dropped += std::exchange(m, 0u);
  for (std::uint64_t& b : r.stage.bytes) b = 0;
  for (std::vector<PeLoad>* loads : {&r.handlers, &r.setups})
    for (PeLoad& load : *loads) {
      dropped += std::exchange(load.messagesSent, 0u);
      load.bytesSent = 0;
    }
  if (dropped > 0) r.note += "; its " + std::to_string(dropped) + " data messages are to itself on one PE, not charged";
  return r;
}

}  // namespace pr::par
