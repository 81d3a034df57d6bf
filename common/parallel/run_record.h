// RunRecord: everything the runtime measured in one run — per PE and per stage busy/idle time,
// task counts, messages and bytes per sender->receiver pair, cache hits and misses, and the
// timeline of task spans. Filled by runtime.cpp (or simulator.cpp); metrics.cpp derives every
// figure from it; run_record_json.cpp writes it as JSON and as a Chrome trace.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/parallel/farm/farm_record.h"
#include "common/parallel/task.h"

namespace pr::par {

// One PE in one stage. busy = inside tasks and message handlers, less the time a task waited
// for a reply; idle = stage wall - busy; syncWaitSeconds = the part of idle after the PE's last
// piece of work until the stage ended (waiting at the end-of-stage synchronisation point).
// Communication time is sendReceiveSeconds (inside Channel calls, part of busy) plus
// messageWaitSeconds (waiting on an empty mailbox while work was still to come, inside a task
// or between tasks; part of idle, never of syncWait).
struct PeStageRecord {
  double busySeconds = 0.0;
  double idleSeconds = 0.0;
  double syncWaitSeconds = 0.0;
  double sendReceiveSeconds = 0.0;
  double messageWaitSeconds = 0.0;
  double commSeconds() const { return sendReceiveSeconds + messageWaitSeconds; }
  std::uint64_t tasks = 0;
  std::uint64_t messagesHandled = 0;
  std::uint64_t messagesSent = 0, bytesSent = 0;
  std::uint64_t messagesReceived = 0, bytesReceived = 0;
  // Task requests and task packets between this PE and the controller or a neighbour; the
  // part of them that crossed between ranks (a PE on another rank than the controller's).
  std::uint64_t schedulingMessages = 0, schedulingBytes = 0;
  std::uint64_t schedulingMessagesBetweenRanks = 0, schedulingBytesBetweenRanks = 0;
  // Replicated read-only data received (scene, photon map), counted once per receiving PE.
  std::uint64_t broadcastsReceived = 0, broadcastBytesReceived = 0;
  // Replicated data this PE's rank made itself (loaded the scene, built the BVH) where one
  // process's PE receives it as a broadcast: a replicated computation, named here, not traffic.
  // Only on the first PE of a rank other than 0, so these and broadcastsReceived together are
  // the copies every P = R x T run of the same shape makes, across ranks or not.
  std::uint64_t replicatedCopies = 0, replicatedBytes = 0;
  std::uint64_t cacheHits = 0, cacheMisses = 0, prefetches = 0;
};

// Messages and bytes from one PE to another within a stage (only non-zero pairs are kept).
struct Traffic {
  int from = 0, to = 0;
  std::uint64_t messages = 0, bytes = 0;
};

// Messages and bytes between PEs through one Channel within a stage, with the channel's kind
// (primitives, pixels, rays, results, requests, data: MessageKind).
struct ChannelTraffic {
  std::string name, kind;
  std::uint64_t messages = 0, bytes = 0;
  std::uint64_t betweenRankMessages = 0, betweenRankBytes = 0;  // the part sent to another rank
};

struct StageRecord {
  std::string name;
  std::string schedule;
  int grain = 1;
  double startSeconds = 0.0;  // since the runtime started
  double wallSeconds = 0.0;
  std::vector<PeStageRecord> pes;
  // The replicated data broadcast before the stage, whatever P: how many broadcasts and their
  // bytes (one copy's). The PEs' broadcastsReceived say who received them at this P (every PE
  // but each broadcast's root), so a P = 1 record still says what another P would receive.
  std::uint64_t broadcasts = 0, broadcastBytes = 0;
  std::vector<Traffic> traffic;
  std::vector<ChannelTraffic> channels;  // the same messages, by channel (only non-zero ones)
  std::vector<TaskInfo> tasks;  // the stage's TaskSet (cost estimates, positions)
  std::vector<int> owners;      // owner-pinned stages: the PE of each task; empty otherwise
  // What the owners alone cannot say (at P = 1 every owner-pinned stage has owners {0}): one
  // of the kinds below, or empty for a stage run under a schedule or pinned by a method's split.
  std::string kind;
  // A stage whose PEs' work is made of cells (RunRecord::cells), dealt to PEs by a rule that is
  // a function of P: the rule (cell_split.h), or empty; how many cells there are (a
  // cell without work has no entry); and the PE that every cell's result goes to (-1: none),
  // which records its storing of other PEs' results as kCollectCell.
  std::string cellSplit;
  int cellCount = 0;
  int cellCollector = -1;
};

// Runtime::runOnEachPe: one task per PE, owner-local work that divides among the owners.
inline constexpr const char* kEachPeStage = "each PE";
// Runtime::runOnOnePe and runOncePerRank: work done once (on each rank), whatever P.
inline constexpr const char* kOnePeStage = "one PE";
// Runtime::runOnEachPeInFull: one task per PE, each doing work that does not shrink with P (a
// full-screen buffer of its own to clear).
inline constexpr const char* kEachPeInFullStage = "each PE in full";

// One task on one PE, or with task = kMessageSpan one message handler, with task = kSetupSpan
// the PE's set-up at the start of a stage (Runtime::runStage with a SetupFn).
inline constexpr TaskId kMessageSpan = -1;
inline constexpr TaskId kSetupSpan = -2;
struct TaskSpan {
  int pe = 0;
  int stage = 0;  // index into RunRecord::stages
  TaskId task = 0;
  double start = 0.0, end = 0.0;  // seconds since the runtime started
  std::uint32_t messagesSent = 0;  // data messages the task sent, for the simulator
  std::uint64_t bytesSent = 0;
  // The part of [start, end) spent waiting for a reply or a message (a data item, a tile's bins),
  // not computing: the simulator replays end - start - waitSeconds and models the wait itself.
  double waitSeconds = 0.0;
};

// An algorithm counter or figure reported per PE (geometry bytes held, primitives duplicated,
// photons stored ...), named "Category/what" (STYLE.md §4). Kept beside the runtime's own
// figures so reports read every number from the same record.
struct CounterRecord {
  std::string name;
  std::vector<double> perPe;  // one value per PE
};

// Part of one task's work on one PE: a cell of the stage's split (a screen tile), measured so
// the simulator can deal the cells again at another P (stage_replay.h); resultBytes is what
// the cell's result sends to the collector when the cell's PE is not the collector. With cell
// = kCollectCell: the collector storing other PEs' results inside its task, resultBytes the
// bytes stored.
inline constexpr int kCollectCell = -1;
struct CellSpan {
  int pe = 0;
  int stage = 0;  // index into RunRecord::stages
  int cell = 0;
  double seconds = 0.0;
  std::uint64_t resultBytes = 0;
};

struct RunRecord {
  int pes = 1;
  // The processes the PEs ran in: PEs [r * pes / ranks, (r + 1) * pes / ranks) on rank r.
  int ranks = 1;
  std::string schedule;
  int grain = 1;
  double wallSeconds = 0.0;  // first stage start to last stage end
  std::vector<StageRecord> stages;
  std::vector<TaskSpan> timeline;
  std::vector<CellSpan> cells;  // only for stages with a cellSplit
  std::vector<CounterRecord> counters;  // in the order first recorded
  std::string error;  // the error that ended the run, empty when it completed
  // A farm run (farm/farm.h): its servers and jobs. Its PEs are then the servers, one per rank.
  std::optional<FarmRecord> farm;
};

// Measured cost of every task of stage `stage` (sum of its spans), for an unbalanced
// data-driven split or a hot-spots order in a later run: the "profile recorded by an earlier run".
std::vector<double> taskCostProfile(const RunRecord& record, int stage);

// JSON (run_record_json.cpp). write* throw pr::InputError when the file cannot be written;
// readRunRecord throws pr::InputError naming the file and the missing or malformed key.
std::string toJsonText(const RunRecord& record);
void writeRunRecord(const RunRecord& record, const std::filesystem::path& file);
RunRecord readRunRecord(const std::filesystem::path& file);
RunRecord runRecordFromJsonText(const std::string& text, const std::string& origin);
// Chrome trace-event format ("X" complete events, one track per PE), for Perfetto or
// chrome://tracing.
void writeChromeTrace(const RunRecord& record, const std::filesystem::path& file);
std::string toChromeTraceText(const RunRecord& record);

}  // namespace pr::par
