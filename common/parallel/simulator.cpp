// The simulator's event loop (virtual time) and its inputs. Uses the very Scheduler classes of
// the thread engine (runtime.cpp): one policy, two drivers. Output is a RunRecord for metrics.cpp.
#include "common/parallel/simulator.h"

#include <algorithm>
#include <bit>
#include <fstream>
#include <memory>
#include <queue>
#include <sstream>

#include "common/parallel/stage_replay.h"
#include "common/util/error.h"

namespace pr::par {

const std::vector<NetworkModel>& networks() {
  // Latencies are one-way per message, including the messaging layer's software overhead;
  // bandwidths are what one link carries. shared-memory is PEs on one machine (a message
  // between threads is a move into a mailbox; between two processes of the 2-core development
  // machine Open MPI measured 0.45 us one way for 8 bytes and 6-8 GB/s for 1 MB in
  // bench_transport); the Ethernet presets take the line rate and a one-way MPI-over-TCP latency of
  // the order the OSU latency benchmark shows on such links (10 us on 10 GbE, 50 us on 1 GbE);
  // 100 Mbit with PVM, 1 ms, is the seed's era (its farms ran on such networks).
  static const std::vector<NetworkModel> kNetworks = {
      {"zero", 0.0, 0.0, "no communication cost (the seed's worked examples)"},
      {"shared-memory", 0.2e-6, 10e9, "PEs of one machine: 0.2 us per message, 10 GB/s"},
      {"10gbe", 10e-6, 1.25e9, "10 Gbit Ethernet cluster, switched: 10 us per message, 1.25 GB/s"},
      {"1gbe", 50e-6, 125e6, "1 Gbit Ethernet, switched: 50 us per message, 125 MB/s"},
      {"100mbit", 1e-3, 12.5e6, "100 Mbit Ethernet with PVM, switched: 1 ms per message, 12.5 MB/s"},
      {"100mbit-shared", 1e-3, 12.5e6,
       "1990s workstation farm, 100 Mbit Ethernet with PVM on one shared segment (one copy at a time): 1 ms per message, 12.5 MB/s",
       true},
  };
  return kNetworks;
}

double NetworkModel::broadcastArrival(int pe, int pes, std::uint64_t messages, std::uint64_t bytes) const {
  if ((messages == 0 && bytes == 0) || pe <= 0 || pes <= 1) return 0.0;
  if (sharedMedium) return pe * seconds(messages, bytes);
  constexpr std::uint64_t kShortBytes = 12288, kMediumBytes = 524288;  // MPICH's thresholds
  constexpr int kMinPesForScatter = 8;
  const std::uint64_t perMessage = messages > 0 ? bytes / messages : bytes;
  if (pes < kMinPesForScatter || perMessage < kShortBytes)
    return double(std::bit_width(static_cast<unsigned>(pe))) * seconds(messages, bytes);
  const int log2Pes = std::bit_width(static_cast<unsigned>(pes - 1));  // ceil(log2 P)
  const bool powerOfTwo = std::has_single_bit(static_cast<unsigned>(pes));
  const double latencies = perMessage < kMediumBytes && powerOfTwo ? 2.0 * log2Pes : double(log2Pes + pes - 1);
  const double moved = 2.0 * double(pes - 1) / double(pes) * double(bytes);
  return double(std::max<std::uint64_t>(messages, 1)) * latencies * latencySeconds +
         (bytesPerSecond > 0.0 ? moved / bytesPerSecond : 0.0);
}

const NetworkModel& networkByName(std::string_view name) {
  std::string names;
  for (const NetworkModel& n : networks()) {
    if (n.name == name) return n;
    names += names.empty() ? "" : ", ";
    names += n.name;
  }
  throw InputError("unknown network '" + std::string(name) + "' (expected one of: " + names + ")");
}

std::string describeNetworks() {
  std::string text;
  for (const NetworkModel& n : networks()) {
    text += "  " + std::string(n.name) + std::string(n.name.size() < 15 ? 15 - n.name.size() : 1, ' ');
    text += std::string(n.description) + "\n";
  }
  return text;
}

namespace {
// What a recorded span computed: its wait for replies and messages depends on the network and
// on other PEs, which the replay models (the messages' costs) instead of repeating it as work.
// (taskCostProfile, run_record_json.cpp, takes the same.)
double computed(const TaskSpan& span) { return std::max(0.0, span.end - span.start - span.waitSeconds); }
}  // namespace

Workload workloadFromRecord(const RunRecord& record, const std::string& origin) {
  Workload w;
  w.schedule = record.schedule;
  w.grain = record.grain;
  w.recordedPes = record.pes;
  w.recordedWallSeconds = record.wallSeconds;
  for (std::size_t s = 0; s < record.stages.size(); ++s) {
    const StageRecord& sr = record.stages[s];
    SimStage stage;
    stage.name = sr.name;
    stage.tasks.tasks = sr.tasks;
    stage.schedule = sr.schedule;
    stage.runtimeSchedule = sr.schedule == record.schedule;
    stage.owners = sr.owners;
    stage.kind = sr.kind;
    // The stage's own figures; a record written before it had them: what any PE received.
    stage.broadcasts = sr.broadcasts;
    stage.broadcastBytes = sr.broadcastBytes;
    for (const PeStageRecord& pe : sr.pes) {
      stage.broadcasts = std::max(stage.broadcasts, pe.broadcastsReceived);
      stage.broadcastBytes = std::max(stage.broadcastBytes, pe.broadcastBytesReceived);
    }
    if (s > 0) {
      const StageRecord& previous = record.stages[s - 1];
      stage.gapBeforeSeconds = std::max(0.0, sr.startSeconds - (previous.startSeconds + previous.wallSeconds));
    }
    const std::size_t n = sr.tasks.size();
    stage.costs.assign(n, 0.0);
    stage.messages.assign(n, 0);
    stage.bytes.assign(n, 0);
    std::vector<char> seen(n, 0);
    std::size_t seenCount = 0;
    for (const TaskSpan& span : record.timeline) {
      if (span.stage != static_cast<int>(s)) continue;
      if (span.task == kMessageSpan || span.task == kSetupSpan) {
        const bool setup = span.task == kSetupSpan;
        if (span.pe < 0 || span.pe >= record.pes)
          throw InputError(origin + ": stage '" + sr.name + "' has a " + (setup ? "set-up" : "message") + " span on PE " +
                           std::to_string(span.pe));
        std::vector<PeLoad>& loads = setup ? stage.setups : stage.handlers;
        if (loads.empty()) loads.resize(static_cast<std::size_t>(record.pes));
        PeLoad& load = loads[static_cast<std::size_t>(span.pe)];
        load.seconds += computed(span);
        load.spans += 1;
        load.messagesSent += span.messagesSent;
        load.bytesSent += span.bytesSent;
        continue;
      }
      if (span.task < 0 || static_cast<std::size_t>(span.task) >= n)
        throw InputError(origin + ": stage '" + sr.name + "' has a span for task " + std::to_string(span.task) +
                         " of " + std::to_string(n));
      stage.costs[span.task] += computed(span);
      stage.messages[span.task] += span.messagesSent;
      stage.bytes[span.task] += span.bytesSent;
      if (!seen[span.task]) seen[span.task] = 1, ++seenCount;
    }
    if (seenCount != n)
      throw InputError(origin + ": stage '" + sr.name + "' has " + std::to_string(n) + " tasks but the timeline has spans for " +
                       std::to_string(seenCount) + " (record the run with its timeline)");
    stage.cellSplit = sr.cellSplit;
    stage.cellCollector = sr.cellCollector;
    if (!sr.cellSplit.empty()) {
      stage.cellCosts.assign(static_cast<std::size_t>(sr.cellCount), 0.0);
      stage.cellBytes.assign(stage.cellCosts.size(), 0);
    }
    // (A stage with a split may have no cell: nothing drawn. Cells of a stage without a split,
    // from a stage that failed before describing them, are not the record's: left out.)
    for (const CellSpan& c : record.cells) {
      if (c.stage != static_cast<int>(s) || sr.cellSplit.empty()) continue;
      PR_CHECK(c.cell >= kCollectCell && c.cell < sr.cellCount, "a cell outside its stage's count");
      if (c.cell == kCollectCell) {
        stage.collectInTaskSeconds += c.seconds;
        continue;
      }
      stage.cellCosts[c.cell] += c.seconds;
      stage.cellBytes[c.cell] = c.resultBytes;
      if (stage.cellCollector >= 0 && c.pe != stage.cellCollector)
        stage.resultsToCollector += 1, stage.resultBytesToCollector += c.resultBytes;
    }
    w.stages.push_back(std::move(stage));
  }
  if (w.stages.empty()) throw InputError(origin + ": the run record has no stages");
  return w;
}

Workload workloadFromCostTable(const std::string& text, const std::string& origin) {
  Workload w;
  SimStage stage;
  stage.name = "costs";
  std::istringstream in(text);
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t') c = ' ';
    std::istringstream fields(line);
    double cost;
    if (!(fields >> cost)) {
      if (line.find_first_not_of(" \r") == std::string::npos) continue;
      throw InputError(origin + ", line " + std::to_string(lineNo) + ": expected a task cost in seconds");
    }
    if (!(cost >= 0.0)) throw InputError(origin + ", line " + std::to_string(lineNo) + ": task cost must be >= 0");
    TaskInfo info{cost, static_cast<float>(stage.tasks.size()), 0.0f};
    float x, y;
    if (fields >> x) {
      if (!(fields >> y)) throw InputError(origin + ", line " + std::to_string(lineNo) + ": position needs x and y");
      info.x = x, info.y = y;
    }
    stage.tasks.tasks.push_back(info);
    stage.costs.push_back(cost);
  }
  if (stage.costs.empty()) throw InputError(origin + ": the cost table has no tasks");
  stage.messages.assign(stage.costs.size(), 0);
  stage.bytes.assign(stage.costs.size(), 0);
  w.stages.push_back(std::move(stage));
  return w;
}

Workload readWorkload(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError("cannot read '" + file.string() + "'");
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  const auto first = s.find_first_not_of(" \t\r\n");
  // Built by appending: GCC 12 warns falsely (-Wrestrict) on "'" + string + "'".
  std::string origin = "'";
  origin += file.string();
  origin += '\'';
  if (first != std::string::npos && s[first] == '{')
    return workloadFromRecord(runRecordFromJsonText(s, origin), origin);
  return workloadFromCostTable(s, origin);
}

std::string formatStageNotes(const std::vector<StageNote>& notes) {
  std::string text;
  for (const StageNote& n : notes) {
    text += "  " + n.stage + ": " + n.rule;
    if (!n.schedule.empty()) text += " (" + n.schedule + ")";
    text += ": " + n.note + "\n";
  }
  return text;
}

namespace {

// The event loop over all stages. runtimeScheduler, when given, replaces the strategy of the
// stages that ran under the run's own schedule.
//
// The message-handler model. A stage's handler work (recorded per PE, or split evenly at
// another P, stage_replay.h) plus the cost of the data messages the handlers sent is charged
// on its PE alongside the tasks: the messages are made by the tasks, so when a PE asks for its
// next task it first handles the share of its handler work that the tasks handed out so far
// (whoever runs them) have generated, task work handed out / total task work; after its last
// task it handles the rest. It assumes messages arrive in step with task work and never wait
// on one another. It is wrong (optimistic) when handler work arrives late — chains of messages
// that outlast the tasks, a ray bouncing between owners after the last tile is done — and when
// one owner's messages depend on another's replies: the real stage then ends later.
Prediction predictWith(const Workload& workload, std::string_view schedule, Scheduler* runtimeScheduler,
                       const SimOptions& options) {
  if (options.pes < 1 || options.pes > 65536)
    throw InputError("simulated PEs must be in [1, 65536], got " + std::to_string(options.pes));
  const int pes = options.pes;
  const ScheduleParams& params = options.params;
  const NetworkModel& net = options.network;

  Prediction prediction;
  RunRecord& record = prediction.record;
  record.pes = pes;
  record.schedule = !schedule.empty() ? std::string(schedule) : workload.schedule;
  record.grain = params.grain;
  double clock = 0.0;  // end of the previous stage
  Grab grab;
  // (virtual time, PE): the PE that is free earliest asks first; ties go to the lower PE id.
  using Event = std::pair<double, int>;

  for (const SimStage& recorded : workload.stages) {
    PR_CHECK(recorded.costs.size() == recorded.tasks.size(), "SimStage costs and tasks differ in size");
    const StageReplay plan = planReplay(recorded, workload.recordedPes, pes, schedule);
    prediction.stages.push_back({recorded.name, std::string(replayRuleName(plan.rule)), plan.schedule, plan.note,
                                 plan.rule == ReplayRule::Excluded});
    // The controlling thread's work between stages is serial: it takes as long at every P.
    clock += recorded.gapBeforeSeconds;
    if (plan.rule == ReplayRule::Excluded) continue;
    const SimStage& stage = plan.stage;
    std::unique_ptr<Scheduler> own;
    Scheduler* scheduler = runtimeScheduler;
    if (!(plan.rule == ReplayRule::Scheduled && plan.runtimeSchedule && runtimeScheduler)) {
      own = plan.rule == ReplayRule::Scheduled ? makeScheduler(plan.schedule) : makeOwnerPinnedScheduler(stage.owners);
      scheduler = own.get();
    }
    const bool traffic = !stage.messages.empty();
    const int stageIndex = static_cast<int>(record.stages.size());
    const double stageStart = clock;
    scheduler->reset(stage.tasks, pes, params);
    StageRecord sr;
    sr.name = stage.name;
    sr.schedule = plan.schedule;
    sr.grain = params.grain;
    sr.startSeconds = stageStart;
    sr.tasks = stage.tasks.tasks;
    sr.owners = plan.rule == ReplayRule::Scheduled ? std::vector<int>{} : stage.owners;
    // Work done once stays serial at any P: its record says so, as the measured one did.
    sr.kind = plan.rule == ReplayRule::SingleOwner ? std::string(kOnePeStage) : stage.kind;
    sr.pes.resize(pes);

    // Handler work per PE (its own seconds plus its sends), and how much of it is done.
    double totalWork = 0.0, handedWork = 0.0;
    for (double c : stage.costs) totalWork += c;
    std::vector<double> handlerSeconds(pes, 0.0), handlerDone(pes, 0.0);
    for (int p = 0; p < pes; ++p) {
      const HandlerLoad& h = plan.handlers[p];
      const double send = net.seconds(h.messagesSent, h.bytesSent);
      handlerSeconds[p] = h.seconds + send;
      PeStageRecord& r = sr.pes[p];
      r.messagesHandled = h.spans;
      r.messagesSent += h.messagesSent;
      r.bytesSent += h.bytesSent;
      r.sendReceiveSeconds += send;
    }
    auto handle = [&](int p, double& t, double upTo) {
      const double due = upTo - handlerDone[p];
      if (due <= 0.0) return;
      if (options.recordTimeline) record.timeline.push_back({p, stageIndex, kMessageSpan, t, t + due, 0u, 0u, 0.0});
      handlerDone[p] = upTo;
      sr.pes[p].busySeconds += due;
      t += due;
    };

    // Each PE starts when its copy of the stage's broadcast data has arrived, with its set-up.
    std::vector<double> lastEnd(pes, stageStart);
    std::vector<Event> initial(pes);
    for (int p = 0; p < pes; ++p) {
      const double arrival = net.broadcastArrival(p, pes, stage.broadcasts, stage.broadcastBytes);
      PeStageRecord& r = sr.pes[p];
      if (p != 0) {  // PE 0 holds the data it broadcasts
        r.broadcastsReceived = stage.broadcasts;
        r.broadcastBytesReceived = stage.broadcastBytes;
      }
      r.messageWaitSeconds += arrival;
      double t = stageStart + arrival;
      const SetupLoad& setup = plan.setups[p];
      if (setup.seconds > 0.0 || setup.messagesSent > 0) {
        const double send = net.seconds(setup.messagesSent, setup.bytesSent);
        const double d = setup.seconds + send;
        if (options.recordTimeline)
          record.timeline.push_back({p, stageIndex, kSetupSpan, t, t + d, static_cast<std::uint32_t>(setup.messagesSent),
                                     setup.bytesSent, 0.0});
        r.busySeconds += d;
        r.sendReceiveSeconds += send;
        r.messagesSent += setup.messagesSent;
        r.bytesSent += setup.bytesSent;
        t += d;
      }
      lastEnd[p] = t;
      initial[p] = {t, p};
    }
    std::priority_queue<Event, std::vector<Event>, std::greater<Event>> ready(std::greater<Event>(), std::move(initial));
    while (!ready.empty()) {
      auto [t, p] = ready.top();
      ready.pop();
      handle(p, t, handlerSeconds[p] * (totalWork > 0.0 ? handedWork / totalWork : 1.0));
      scheduler->next(p, t, grab);
      // Steal requests answered empty: a round trip each, waited for one after the other.
      t += grab.emptyAnswers * net.seconds(2, kTaskRequestBytes + kTaskPacketHeaderBytes);
      PeStageRecord& r = sr.pes[p];
      const std::uint64_t messages = grab.requests + grab.packets;
      if (grab.from != p && messages > 0) {  // a search that found no task sent its requests too
        r.schedulingMessages += messages;
        r.schedulingBytes += grab.transferBytes();
      }
      if (grab.tasks.empty()) {  // this PE is done with the stage's tasks: the rest of its messages
        handle(p, t, handlerSeconds[p]);
        lastEnd[p] = std::max(lastEnd[p], t);
        continue;
      }
      const int packets = grab.packets - grab.emptyAnswers;  // those that brought tasks
      if (grab.from != p && grab.blocking && packets > 0) {
        // Idle until the first packet arrives; refills in the same answer travel while it computes.
        const std::uint64_t first = (grab.requests > grab.emptyAnswers ? kTaskRequestBytes : 0) +
                                    kTaskPacketHeaderBytes + grab.moved / std::uint64_t(packets) * kTaskEntryBytes;
        t += net.seconds((grab.requests > grab.emptyAnswers ? 1 : 0) + 1, first);
      }
      for (TaskId id : grab.tasks) handedWork += stage.costs[id];
      for (TaskId id : grab.tasks) {
        double d = stage.costs[id];
        if (traffic && stage.messages[id] > 0) {
          const double send = net.seconds(stage.messages[id], stage.bytes[id]);
          d += send;
          r.sendReceiveSeconds += send;
          r.messagesSent += stage.messages[id];
          r.bytesSent += stage.bytes[id];
        }
        if (options.recordTimeline)
          record.timeline.push_back({p, stageIndex, id, t, t + d, traffic ? stage.messages[id] : 0u,
                                     traffic ? stage.bytes[id] : 0u, 0.0});
        t += d;
        r.busySeconds += d;
        r.tasks += 1;
        scheduler->finished(p, id, d);
      }
      lastEnd[p] = t;
      ready.push({t, p});
    }
    const double end = std::max(stageStart, *std::max_element(lastEnd.begin(), lastEnd.end()));
    sr.wallSeconds = end - stageStart;
    for (int p = 0; p < pes; ++p) {
      sr.pes[p].idleSeconds = std::max(0.0, sr.wallSeconds - sr.pes[p].busySeconds);
      sr.pes[p].syncWaitSeconds = end - lastEnd[p];
    }
    record.stages.push_back(std::move(sr));
    clock = end;
  }
  record.wallSeconds = clock;
  return prediction;
}

}  // namespace

Prediction predict(const Workload& workload, std::string_view schedule, const SimOptions& options) {
  return predictWith(workload, schedule, nullptr, options);
}

RunRecord simulate(const Workload& workload, std::string_view schedule, const SimOptions& options) {
  return predict(workload, schedule, options).record;
}

Prediction predict(const Workload& workload, Scheduler& scheduler, const SimOptions& options) {
  return predictWith(workload, scheduler.name(), &scheduler, options);
}

RunRecord simulate(const Workload& workload, Scheduler& scheduler, const SimOptions& options) {
  return predict(workload, scheduler, options).record;
}

}  // namespace pr::par
