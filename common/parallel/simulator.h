// Simulator: the scheduling strategies of schedulers/ driven in virtual time, for any P from 1
// to 1024, from per-task costs (a recorded run's timeline or a cost table) and a communication
// model (latency per message + bytes / bandwidth). It answers "what would this scene do on 30
// machines, or 300?" from a laptop. The same Scheduler objects as the thread engine make the
// decisions; the result is a RunRecord, so metrics.cpp derives every figure the same way.
// A recorded stage is replayed with the strategy it ran with, owner-pinned stages by the
// scaling rules of stage_replay.h; message handlers, broadcasts and the controlling thread's
// time between stages are charged too (predict() below says how).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/run_record.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/task.h"

namespace pr::par {

struct NetworkModel {
  std::string_view name;
  double latencySeconds = 0.0;  // per message
  double bytesPerSecond = 0.0;  // 0: infinite bandwidth
  std::string_view description;
  // One medium that carries one copy at a time (an Ethernet segment on a hub, a bus): the
  // seed's setting, PVM over one segment. Otherwise the network is switched: disjoint pairs of
  // PEs exchange messages at the same time.
  bool sharedMedium = false;

  double seconds(std::uint64_t messages, std::uint64_t bytes) const {
    return messages * latencySeconds + (bytesPerSecond > 0.0 ? bytes / bytesPerSecond : 0.0);
  }
  // Replicated data (the scene, a photon map: `messages` messages of `bytes` in all per PE)
  // reaches PE pe of `pes` this long after the stage could start, broadcast from PE 0, which
  // holds it. On a shared medium PE 0 sends the P - 1 copies one after another, PE 1's first.
  // On a switched network the broadcast is MPI's, as MPICH's MPI_Bcast chooses its algorithm
  // (Thakur, Rabenseifner and Gropp 2005): a binomial tree for messages under 12 KiB or fewer
  // than 8 PEs (numbered here so that PE p has the data after bit_width(p) steps of latency +
  // bytes/bandwidth; MPICH serves the farthest subtree first, which changes which PE is early,
  // not when the last one has it); otherwise a scatter followed by an all-gather (van de
  // Geijn), by recursive doubling for messages under 512 KiB on a power-of-two P (2 log2 P
  // latencies), else around a ring (log2 P + P - 1 latencies), each moving 2 (P - 1) / P of
  // the bytes, every PE done at the end. The algorithm is chosen by the stage's mean message
  // size (the record keeps a stage's broadcasts as one count and one byte total). This is a
  // prediction for a program that broadcasts with MPI: the runtime's own broadcastToRanks sends
  // rank 0's data to each other rank in turn. Task packets are not held up by the broadcast (the
  // scheduler is taken to have a link of its own), and a stage lasts until every PE has its
  // copy, work or not.
  double broadcastArrival(int pe, int pes, std::uint64_t messages, std::uint64_t bytes) const;
};
// Presets: zero, shared-memory, 10gbe, 1gbe, 100mbit (switched), 100mbit-shared (a 1990s
// workstation farm on one Ethernet segment).
const std::vector<NetworkModel>& networks();
// Throws pr::InputError naming the unknown network and listing the presets.
const NetworkModel& networkByName(std::string_view name);
std::string describeNetworks();

// Work of one PE in one stage besides its tasks, as recorded: its message handlers (the spans
// with task == kMessageSpan) or its set-up (task == kSetupSpan, Runtime::runStage with a
// SetupFn): their summed seconds (less waiting, as a task's cost), how many spans (messages handled; one set-up), and the data
// messages they sent.
struct PeLoad {
  double seconds = 0.0;
  std::uint64_t spans = 0;
  std::uint64_t messagesSent = 0, bytesSent = 0;
};
using HandlerLoad = PeLoad;
using SetupLoad = PeLoad;

// One stage's work. tasks is what the scheduler sees (estimates, positions); costs are the
// seconds each task really computes (a recorded span less its waiting for replies: the replay
// charges the network for the messages instead); messages/bytes the data messages each task sends (empty:
// none). A sender pays latency + bytes/bandwidth for its messages inside the task. The fields
// after them come from a run record and are empty or zero for a cost table; stage_replay.h
// says how each is replayed at another P.
struct SimStage {
  std::string name;
  TaskSet tasks;
  std::vector<double> costs;
  std::vector<std::uint32_t> messages;
  std::vector<std::uint64_t> bytes;
  std::string schedule;         // the strategy the stage ran with; empty: the one simulate() is given
  bool runtimeSchedule = true;  // it ran under the run's own schedule, which --schedule replaces
  std::vector<int> owners;      // owner-pinned stages: the PE of each task in the recorded run
  std::string kind;             // StageRecord::kind: each PE, one PE, or empty
  std::vector<HandlerLoad> handlers;  // one per recorded PE; empty: no message handled
  std::vector<SetupLoad> setups;      // one per recorded PE; empty: the stage has no set-up
  // Replicated read-only data each PE received before the stage (messages and bytes per PE).
  std::uint64_t broadcasts = 0, broadcastBytes = 0;
  // The controlling thread's time between the previous stage's end (or the first stage's
  // start) and this stage's start: collating results, building the next stage's inputs.
  double gapBeforeSeconds = 0.0;
  // A stage made of cells (StageRecord::cellSplit, cell_split.h): the rule, each cell's
  // measured seconds and result bytes (by cell index, every cell), the collector, its storing
  // of the results of cells on other PEs inside its tasks (what it stored in its message
  // handlers is in `handlers`), and how many results, of how many bytes, went to it.
  std::string cellSplit;
  int cellCollector = -1;
  std::vector<double> cellCosts;
  std::vector<std::uint64_t> cellBytes;
  double collectInTaskSeconds = 0.0;
  std::uint64_t resultsToCollector = 0, resultBytesToCollector = 0;
};
struct Workload {
  std::vector<SimStage> stages;
  std::string schedule;  // recorded schedule, empty for a cost table
  int grain = 1;
  int recordedPes = 0;   // 0 for a cost table
  double recordedWallSeconds = 0.0;
};

// Each task's cost is its measured span; estimates and positions are the recorded TaskSet's.
// Throws pr::InputError when a stage has tasks but the record has no timeline for them.
Workload workloadFromRecord(const RunRecord& record, const std::string& origin);
// A cost table: one task per line, "cost" or "cost x y" (seconds, position); '#' starts a
// comment. One stage named "costs"; the estimate of each task is its cost.
Workload workloadFromCostTable(const std::string& text, const std::string& origin);
// A JSON run record (written with --metrics) or a cost table, told apart by the first character.
Workload readWorkload(const std::filesystem::path& file);

struct SimOptions {
  int pes = 1;
  ScheduleParams params;
  NetworkModel network;   // zero cost by default
  bool recordTimeline = false;
};

// How each recorded stage was replayed (stage_replay.h): the rule, the strategy, and the
// rule's assumption or the reason the stage was left out of the prediction.
struct StageNote {
  std::string stage;
  std::string rule;      // replayRuleName()
  std::string schedule;  // the strategy the replay ran; empty for an excluded stage
  std::string note;
  bool excluded = false;
};
struct Prediction {
  RunRecord record;  // excluded stages are not in it
  std::vector<StageNote> stages;  // every stage of the workload, in order
};
// "stage: rule (schedule): note" lines, for parrender simulate.
std::string formatStageNotes(const std::vector<StageNote>& notes);

// Runs every stage of the workload in virtual time at options.pes PEs. `schedule` is the
// strategy for the stages that ran under the run's own schedule (all stages of a cost table);
// empty: each stage's recorded one. Stages that ran with another strategy keep theirs, and
// owner-pinned stages follow the rules of stage_replay.h. Within a stage: PEs ask for work in
// order of virtual time, ties by lower PE id; a PE starts only when its copy of the stage's
// broadcast data has arrived (NetworkModel::broadcastArrival) and its set-up is done; a PE waiting for a task packet
// is idle for the request and packet latencies plus the packet's bytes over the bandwidth
// (refills ahead of need are counted as traffic but not waited for); data messages sent by a
// task or handler are charged to the sender; message-handler work is charged alongside the
// tasks (see simulate() in simulator.cpp). Between stages the controlling thread's recorded
// time is replayed serially. wallSeconds of the result is the makespan.
// Throws pr::InputError when a stage has no schedule (a cost table and an empty `schedule`).
Prediction predict(const Workload& workload, std::string_view schedule, const SimOptions& options);
RunRecord simulate(const Workload& workload, std::string_view schedule, const SimOptions& options);
// The same with a scheduler object for the stages under the run's own schedule.
Prediction predict(const Workload& workload, Scheduler& scheduler, const SimOptions& options);
RunRecord simulate(const Workload& workload, Scheduler& scheduler, const SimOptions& options);

}  // namespace pr::par
