// Runtime: P processing elements on threads, the system controller that hands out tasks
// through a Scheduler, and the measurements (busy/idle per PE and stage, task spans, message
// counts) that every renderer's run record is made of. The heart of common/parallel; every
// renderer runs on it (seed chapters 2-4, shared/DESIGN.md "Parallel runtime").
//
// How a renderer uses it
// ----------------------
// A stage is a TaskSet (one task per PDI: tile, primitive batch, ray batch) plus a work
// function called as work(pe, taskId) on the PE the schedule chose. PEs talk only through
// Channels; a Channel constructed with a handler makes the stage message-driven: the stage
// ends when every task has run and every message (and the messages its handler sent) has been
// handled (termination.h). The runtime, not the algorithm, times tasks, handlers and set-ups.
//
//   par::Runtime rt(8, "spiral", scheduleOptions.params);   // or from --schedule/--grain
//   par::Channel<RayBatch> rays(rt, "rays", par::MessageKind::Rays, [&](par::Pe& pe, RayBatch&& b) { trace(pe, b); });
//   rt.recordBroadcast(sceneBytes);                         // the scene, from PE 0 to every other PE
//   rt.runStage("trace", par::TaskSet::grid(tilesX, tilesY), [&](par::Pe& pe, par::TaskId t) {
//     for (RayBatch& b : primaryRays(t)) rays.send(pe, ownerOf(b), std::move(b));  // counted as its encoding
//   });
//   par::writeRunRecord(rt.record(), "run.json");           // per-PE busy/idle, traffic, timeline
//
// The system controller's role is split in two: the Scheduler hands out tasks (its requests
// and task packets are counted as scheduling traffic), and the renderer's controlling thread
// collates results between stages (Channel::drain), after runStage's barrier.
//
// An exception thrown by a task, handler or set-up stops every PE at its next task boundary (a
// set-up already running is not interrupted: the stage ends when it returns) and is rethrown (the first one, unchanged) by runStage; RunRecord::error names stage, PE and task.
// P may exceed the core count: idle PEs block on a condition variable, they do not spin. A PE
// waiting inside a task for another PE's reply (await_reply.h) polls, serving the requests
// addressed to it meanwhile, and yields its core between polls.
// The PE threads live for the runtime's lifetime (started by the first stage): a stage costs a
// wake-up and a barrier, not P thread creations (bench_runtime section 6).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstddef>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "common/parallel/pe.h"
#include "common/parallel/run_record.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/task.h"
#include "common/parallel/termination.h"
#include "common/parallel/transport.h"

namespace pr::par {

class Transport;

struct RuntimeOptions {
  int pes = 1;                      // P: every PE of the run, on every rank
  std::string schedule = "demand";  // registry name (schedulers/registry.cpp)
  ScheduleParams params;
  bool recordTimeline = true;       // keep one TaskSpan per task, handled message and set-up
  // The ranks of the run (not owned; nullptr or one rank: this process holds every PE). With
  // R ranks, this rank runs PEs [rank * P/R, (rank + 1) * P/R) and every rank's controlling
  // thread runs the same stages (rank_stage.cpp: how a stage ends across ranks).
  Transport* transport = nullptr;
};

// What a message carries, for the traffic-by-kind figures of the run record: primitives
// (sort-first and sort-middle), pixels (sort-last compositing), rays (rays, ray queries and
// hit records), results (image assembly: tiles, regions, film blocks), requests (asking
// another PE for something) and data (data items fetched through a DataManager).
enum class MessageKind : std::uint8_t { Primitives, Pixels, Rays, Results, Requests, Data };
std::string_view toString(MessageKind kind);

// A mailbox set the runtime polls on behalf of a PE (implemented by Channel<T>). Every channel
// counts the messages between different PEs sent through it; the runtime books them per stage.
class ChannelBase {
 public:
  ChannelBase(std::string name, MessageKind kind) : name_(std::move(name)), kind_(kind) {}
  virtual ~ChannelBase() = default;
  const std::string& name() const { return name_; }
  MessageKind kind() const { return kind_; }
  // Its number among the runtime's channels, in the order they were made: the same on every
  // rank, since every rank makes the same channels (set by Runtime::attach).
  std::uint32_t id() const { return id_; }
  void setId(std::uint32_t id) { id_ = id; }
  // Called by Channel::send for a message between two PEs, on two ranks or one.
  void countSent(std::size_t bytes, bool betweenRanks) {
    messages_.fetch_add(1, std::memory_order_relaxed);
    bytes_.fetch_add(bytes, std::memory_order_relaxed);
    if (!betweenRanks) return;
    remoteMessages_.fetch_add(1, std::memory_order_relaxed);
    remoteBytes_.fetch_add(bytes, std::memory_order_relaxed);
  }
  // The counts since the last call (by the runtime, between stages): messages, bytes, and the
  // messages and bytes of them sent to another rank.
  std::array<std::uint64_t, 4> takeCounts() {
    return {messages_.exchange(0, std::memory_order_relaxed), bytes_.exchange(0, std::memory_order_relaxed),
            remoteMessages_.exchange(0, std::memory_order_relaxed), remoteBytes_.exchange(0, std::memory_order_relaxed)};
  }
  virtual bool pending(int pe) const = 0;
  // Pops one message for pe and runs the handler on it; false when there was none.
  virtual bool handleOne(Pe& pe) = 0;
  // A message from another rank's PE `from` to this rank's PE `to`, as its encoding: decoded
  // and put in to's mailbox. counted: the bytes its sender booked.
  virtual void deliver(int from, int to, std::span<const std::byte> encoding, std::size_t counted) = 0;

 private:
  std::string name_;
  MessageKind kind_;
  std::uint32_t id_ = 0;
  std::atomic<std::uint64_t> messages_{0}, bytes_{0}, remoteMessages_{0}, remoteBytes_{0};
};

// What runStage throws on a rank whose PEs did not fail when a PE on another rank did: the
// stage ended there, and that rank reports the failure (its text is what()).
class FailedElsewhere : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Runtime {
 public:
  using TaskFn = std::function<void(Pe&, TaskId)>;
  using SetupFn = std::function<void(Pe&)>;

  // Throws pr::InputError for pes outside [1, 4096] or an unknown schedule.
  explicit Runtime(RuntimeOptions options);
  Runtime(int pes, std::string schedule = "demand", ScheduleParams params = ScheduleParams())
      : Runtime(RuntimeOptions{pes, std::move(schedule), params, true}) {}
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  int pes() const { return options_.pes; }
  const RuntimeOptions& options() const { return options_; }
  // The ranks and this process's place among them; PE ids are global.
  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  int firstLocalPe() const { return rank_ * localPes_; }
  int localPes() const { return localPes_; }
  bool isLocal(int pe) const { return pe >= firstLocalPe() && pe < firstLocalPe() + localPes_; }
  int rankOf(int pe) const { return pe / localPes_; }

  // Runs one stage on all PEs and returns when it is over (a barrier). Called by the
  // renderer's controlling thread, never from inside a task. The first overload uses the
  // runtime's schedule (options().schedule).
  void runStage(std::string_view name, const TaskSet& tasks, const TaskFn& work);
  void runStage(std::string_view name, const TaskSet& tasks, Scheduler& scheduler, const TaskFn& work);
  // The same, with each PE first running setup(pe): owner-local preparation that this PE's tasks
  // and message handlers need (build my BVH), done inside the stage so that a PE that is ready
  // starts on tasks while another still prepares, instead of every PE waiting at a barrier for
  // the slowest set-up. Messages sent to a PE in its set-up wait until it is done (unless the
  // set-up itself waits for a reply, await_reply.h, which handles them). A set-up may send; it
  // counts as outstanding work (termination.h) until it returns. Recorded as a span with task =
  // kSetupSpan; the simulator replays it before the PE's first task.
  void runStage(std::string_view name, const TaskSet& tasks, const SetupFn& setup, const TaskFn& work);
  // Task t runs on PE owner[t] (owner-pinned: a region, voxel or buffer runs where its data is),
  // whatever the runtime's schedule; the record names the stage's schedule "owner-pinned" and
  // keeps the owners, so the simulator can say how the method would pin them at another P.
  void runPinned(std::string_view name, const TaskSet& tasks, std::vector<int> owner, const TaskFn& work);
  // One task on each PE, task p on PE p: owner-local work (build my BVHs, clear my buffers,
  // composite my rectangle) that no other PE may do for it (shared/DESIGN.md rule 1).
  void runOnEachPe(std::string_view name, const std::function<void(Pe&)>& work);
  // The same for work each PE does in full whatever P (clear my full-screen buffer): the record
  // says so (kEachPeInFullStage), and the simulator gives every PE at another P the recorded
  // mean instead of splitting the total.
  void runOnEachPeInFull(std::string_view name, const std::function<void(Pe&)>& work);
  // One task on the first PE of every rank (PE 0 alone on one rank): work each rank does for
  // itself from what it already holds (the world BVH from the scene every rank loaded), a
  // replicated computation the record shows on each rank's first PE, not a transfer.
  void runOncePerRank(std::string_view name, const std::function<void(Pe&)>& work);
  // One task, on PE pe: serial work (a data split, the world BVH) timed as a stage of its own,
  // which the simulator keeps on one PE at any P.
  void runOnOnePe(std::string_view name, int pe, const std::function<void(Pe&)>& work);

  // Replicated read-only data (scene, photon map) of `bytes`, held by PE `root` and sent once
  // to every other PE: counted as one broadcast message per receiving PE in the next stage run
  // (root receives nothing, so a P = 1 run has no broadcast traffic).
  void recordBroadcast(std::size_t bytes, int root = 0);
  // Replicated data every rank's first PE received as a booked transfer (broadcastToRanks),
  // read by the rank's other PEs: one broadcast message per receiving PE within each rank,
  // none between ranks. On one rank it is recordBroadcast: PE 0 holds it, every other PE
  // receives a copy.
  void recordBroadcastWithinRanks(std::size_t bytes);
  // Replicated data every rank made itself (the scene it loaded, a BVH it built from it), read
  // by the rank's other PEs: booked as recordBroadcastWithinRanks, and on each other rank's
  // first PE as a replicated copy (PeStageRecord::replicatedBytes), not traffic. So a P = R x T
  // run books P - 1 copies whatever R: broadcasts within ranks, replicated between them.
  void recordReplicated(std::size_t bytes);

  // A stage whose PEs' work is made of cells dealt by a rule that depends on P (cell_split.h:
  // static screen tiles dealt round-robin, rows in strips): inside its tasks each PE records
  // each cell's seconds and what the cell's result sends to the collector (kCollectCell: the
  // collector's storing of others' results), and after it describeCells names the rule, the
  // number of cells and the collector (-1: none), so the simulator can deal the cells again at
  // another P (stage_replay.h). The cells are kept with the timeline only (the split is named
  // either way).
  void recordCell(const Pe& pe, int cell, double seconds, std::uint64_t resultBytes);
  void describeCells(std::string_view split, int cells, int collector);

  // Adds value to the named per-PE counter (created at zero for every PE on first use).
  // Thread-safe: callable from tasks, handlers or the controlling thread.
  void addCounter(std::string_view name, int pe, double value);

  const RunRecord& record() const { return record_; }
  // Across ranks, called by every rank between stages (collectives.cpp; each waits for another
  // rank at most timeoutSeconds). gatherRecord, after the last stage: on rank 0, record()
  // becomes the record of every rank's PEs on rank 0's clock; elsewhere it stays this rank's.
  // sumAcrossRanks: values becomes the element-wise sum of every rank's values (each rank
  // holding what its PEs computed and zeros elsewhere); on one rank it is left as it is.
  const RunRecord& gatherRecord(double timeoutSeconds = 300.0);
  // Inside a runOncePerRank stage, on each rank's first PE: data, held on rank 0, becomes every
  // other rank's (rank 0 sends it to each, and no longer holds it; the wait for it is booked as
  // waiting). A real broadcast, booked in this stage as one copy to each other rank's first
  // PE, between ranks (what the rest of a rank's PEs read of it, the rank makes of it first
  // and books where it shares that: recordBroadcastWithinRanks). Nothing moves on one rank.
  void broadcastToRanks(Pe& pe, Bytes& data, double timeoutSeconds = 300.0);
  void sumAcrossRanks(std::span<double> values, double timeoutSeconds = 300.0);
  // Seconds since the runtime was created (steady clock).
  double now() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
  }

  // ---- for Channel and DataManager, on PE threads during a stage ----
  // Counts one message from pe `from` to pe `to` (nothing for a message to oneself); the
  // receiver's figures only when it is on this rank (otherwise its rank counts them on arrival).
  void countMessage(int from, int to, std::size_t bytes);
  // A message from a local PE to a PE on another rank: `framed` is kFrameBytes of room for the
  // runtime's header, then the message's encoding. Counted by the caller (countMessage).
  static constexpr std::size_t kFrameBytes = 32;
  void sendToRank(const ChannelBase& channel, int from, int to, Bytes framed, std::size_t counted);
  // Empty storage with room for a message of `bytes` to another rank (Transport::storage).
  Bytes sendStorage(std::size_t bytes) { return options_.transport->storage(bytes); }
  // On arrival of a message from another rank: the receiving PE's figures.
  void countReceived(int to, std::size_t bytes);
  OutstandingWork& outstanding() { return outstanding_; }
  void ring(int pe);  // wakes pe if it waits for messages
  // Every channel registers (counting); handled ones are also polled for their messages.
  void attach(ChannelBase* channel, bool handled);
  void detach(ChannelBase* channel);
  bool inStage() const { return inStage_; }
  // True from the first failure in the current stage until the next stage starts: a task that
  // waits inside itself for other PEs (a reply, a handshake) must stop waiting, since a failed
  // PE never answers; what it throws then is dropped, the first error is the one rethrown.
  bool aborting() const { return abort_.load(std::memory_order_acquire); }
  // Inside a stage, on a PE that waits inside a task for a message from another rank: moves
  // what has arrived from other ranks into this rank's mailboxes (one thread at a time; the
  // others return at once). True when it did something; false on a runtime of one rank.
  bool pumpMessages() { return ranks_ > 1 && pumpRankStage(); }
  // Inside a task on PE pe that waits for another PE: handles one message waiting for pe in
  // any handled channel, requests first (another waiting PE may need the answer); true when it
  // did. Part of the task's busy time, not a span of its own. A handler must not itself wait
  // for a reply (it would serve, and so run handlers, inside a handler).
  bool serveOne(Pe& pe);

 private:
  struct Doorbell;
  struct StageJob {
    Scheduler* scheduler = nullptr;
    const TaskFn* work = nullptr;
    const SetupFn* setup = nullptr;  // none: the PEs start on tasks at once
    int stage = 0;
    const std::string* name = nullptr;
  };

  // owners: the PE of each task of an owner-pinned stage (kept in the record), else empty.
  void runStage(std::string_view name, const TaskSet& tasks, Scheduler& scheduler, const SetupFn* setup,
                const TaskFn& work, std::vector<int> owners);
  void startWorkers();
  void workerMain(int p);
  void peLoop(int p, const StageJob& job);
  template <class Work>
  std::optional<double> timed(Pe& pe, TaskId task, std::vector<TaskSpan>& spans, Work&& work);
  bool handleMessages(Pe& pe, std::vector<TaskSpan>& spans);
  void waitForWork(int p);
  static void confirmWait(PeCounters& c);
  void ringAll();
  void fail(int p, const std::string& stage, TaskId task, std::exception_ptr error);
  // Across ranks (rank_stage.cpp): the stage is over when termination detection says so.
  bool stageOver() const {
    return ranks_ == 1 ? outstanding_.finished() : rankStage_.over.load(std::memory_order_acquire);
  }
  // askController: a PE on a rank other than 0 under a strategy rank 0 holds; reports: the
  // tasks it finished since it last asked, sent with the request.
  struct TaskReport {
    TaskId task;
    double seconds;
  };
  bool awaitAnswer(Pe& pe, Grab& grab, std::vector<TaskSpan>& spans);
  // Scheduling traffic of PE pe (its part between ranks too), counted as it happens.
  void bookScheduling(int pe, std::uint64_t messages, std::uint64_t bytes, bool betweenRanks);
  void nextTasks(Pe& pe, Scheduler& scheduler, bool askController, Grab& grab, std::vector<TaskSpan>& spans,
                 std::vector<TaskReport>& reports, bool& asked);
  void driveRankStage(int stage);
  bool pumpRankStage();
  void handleRankMessage(Envelope& envelope);
  void sendControl(int to, std::uint32_t type, int stage, int a, Bytes payload = {});

  RuntimeOptions options_;
  int rank_ = 0, ranks_ = 1, localPes_ = 1;
  std::unique_ptr<Scheduler> schedule_;
  std::chrono::steady_clock::time_point epoch_;
  RunRecord record_;

  std::vector<ChannelBase*> channels_;    // with a handler: polled by the PE loop
  std::vector<ChannelBase*> registered_;  // all: their traffic goes in the stage record
  std::mutex channelMutex_;
  std::vector<PeCounters> counters_;
  std::vector<std::atomic<std::uint64_t>> pairMessages_, pairBytes_;  // P x P, row = sender
  std::vector<std::unique_ptr<Doorbell>> bells_;
  std::vector<std::vector<TaskSpan>> spans_;
  std::vector<std::vector<CellSpan>> cells_;  // per PE, this stage's (recordCell)
  std::size_t lastStageCells_ = 0;           // where the last stage's cells begin in record_.cells
  OutstandingWork outstanding_;
  std::atomic<bool> abort_{false};
  bool inStage_ = false;
  struct PendingBroadcast {
    std::size_t bytes;
    int root;
    enum class To { EveryPe, OtherRanksFirstPe, WithinRanks, WithinRanksReplicated };
    To to = To::EveryPe;  // every PE but root; each other rank's first PE (broadcastToRanks);
                          // every PE but its rank's first (recordBroadcastWithinRanks); that,
                          // and each other rank's first PE made its own (recordReplicated)
  };
  std::vector<PendingBroadcast> pendingBroadcasts_;

  // The PE threads and the stage hand-over: the controlling thread publishes job_ and bumps
  // generation_; each worker runs it once and the last one to finish wakes the controller.
  std::vector<std::thread> workers_;
  std::mutex stageMutex_;
  std::condition_variable stageStart_, stageDone_;
  // Written under stageMutex_, read without it by the short spin before a blocking wait.
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<int> running_{0};
  bool shutdown_ = false;
  StageJob job_;

  std::mutex counterMutex_;
  std::mutex errorMutex_;
  std::exception_ptr error_;

  // A stage across ranks: this rank's part of the termination detection (Mattern's four
  // counters: data messages sent to and received from other ranks), the messages that came
  // early for a later stage, and the task answers rank 0's controller sent to this rank's PEs.
  struct RankStage {
    std::atomic<bool> over{false};
    std::atomic<bool> pumping{false};  // the stage's messages may be pumped (driveRankStage runs)
    std::atomic<std::uint64_t> sent{0}, received{0};
    bool failedHere = false, announced = false, spent = false;
    std::mutex answerMutex;
    std::vector<std::optional<Grab>> answers;  // per local PE
    // Under pumpMutex: the stage, the messages that came early, the waves.
    std::mutex pumpMutex;
    int stage = 0;
    std::vector<Envelope> early;
    std::int32_t wave = 0, probe = -1;  // rank 0's wave; elsewhere the probe to answer
    bool waveOpen = false, havePrevious = false;
    int replies = 0;
    std::uint64_t totalSent = 0, totalReceived = 0, previousSent = 0, previousReceived = 0;
  };
  RankStage rankStage_;
  std::vector<ChannelBase*> channelsById_;  // every channel ever attached, by id (null once gone)
};

}  // namespace pr::par
