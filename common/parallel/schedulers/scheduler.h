// Scheduler: how a PE gets its next task(s) — the computational models and task-management
// strategies of the seed (chapter 3: data-driven, demand-driven, hybrid, task manager,
// distributed task management, preferred bias). One implementation per file beside this one,
// one line each in registry.cpp. The same object is driven by the thread engine (runtime.cpp,
// real time, PEs calling concurrently) and by the simulator (simulator.cpp, virtual time).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/task.h"
#include "common/util/registry.h"

namespace pr::par {

// The system controller: the source of tasks that do not come from another PE.
inline constexpr int kController = -1;

// Sizes of the scheduling messages, as a distributed-memory implementation would send them:
// a request names the PE; a task packet has a header and one task id per task.
inline constexpr std::size_t kTaskRequestBytes = 16;
inline constexpr std::size_t kTaskPacketHeaderBytes = 16;
inline constexpr std::size_t kTaskEntryBytes = sizeof(TaskId);

// The strategy's parameters; the number of PEs is not one of them (reset() is told it).
struct ScheduleParams {
  int grain = 1;               // tasks per task packet (--grain)
  int bufferDepth = 2;         // task-manager local pool, in packets (--buffer-depth)
  double staticFraction = 0.5; // hybrid: share of tasks split statically (--static-fraction)
  std::uint64_t seed = 1;      // random order
};

// The answer to "PE p asks for work". tasks are run now, in order, by the asking PE. The
// transfer that brought them (requests, packets task packets, moved tasks, from the controller or
// another PE) is what the runtime counts as scheduling traffic and the simulator charges on
// the network model. blocking: the PE waits for the first packet (and its request); further
// packets in the same answer are refills requested ahead of need (a task manager's), whose
// latency is off the critical path. blocking = false: even the first packet was already local.
struct Grab {
  std::vector<TaskId> tasks;  // empty: this PE will get no more tasks in this stage
  int from = kController;     // kController, the asking PE itself (local pool), or a victim PE
  int requests = 0;           // request messages sent (none for an unprompted static portion)
  int packets = 0;
  std::size_t moved = 0;
  // Of those requests and packets: steal requests another PE answered with an empty packet
  // (distributed's search), one round trip each that the asking PE waits for. A grab with no
  // tasks may still carry them: the search that found every pool empty cost its messages.
  int emptyAnswers = 0;
  bool blocking = true;
  // Across ranks, for a strategy with local pools (Scheduler::localPoolsAcrossRanks), no tasks
  // yet and: askPe >= 0, a stealing search reached PE askPe on another rank (the runtime asks
  // that PE's rank, stealFrom there, hands the answer to stolen() and asks next() again); or
  // askPe == kAwaitRefill, the PE's local pool is empty and a refill is on its way (the runtime
  // waits for it, then asks next() again). -1: nothing to ask.
  static constexpr int kAwaitRefill = -2;
  int askPe = -1;
  // Refill requests the runtime sends rank 0 now, without waiting (a task manager's local pool
  // on another rank; answered by supplyPacket there and handed to refill() here).
  int refillRequests = 0;

  void clear() {
    tasks.clear();
    from = kController;
    requests = 0;
    packets = 0;
    moved = 0;
    emptyAnswers = 0;
    blocking = true;
    askPe = -1;
    refillRequests = 0;
  }
  // The bytes of its requests, packets and moved task ids (the modelled sizes above).
  std::uint64_t transferBytes() const {
    return requests * kTaskRequestBytes + packets * kTaskPacketHeaderBytes + moved * kTaskEntryBytes;
  }
};

class Scheduler {
 public:
  virtual ~Scheduler() = default;
  virtual std::string_view name() const = 0;  // its registry name
  // Prepares a stage on pes PEs: computes any static assignment. Called once, before any PE
  // asks, from one thread. Data-driven assignments are a pure function of (tasks, pes, params),
  // so the thread engine and the simulator produce the same ones.
  virtual void reset(const TaskSet& tasks, int pes, const ScheduleParams& params) = 0;
  // PE pe asks for its next task(s) at time now (seconds; real or virtual). Different PEs call
  // concurrently; implementations synchronise themselves. Each task id is handed out exactly
  // once per reset. An empty answer is final for that PE.
  virtual void next(int pe, double now, Grab& out) = 0;
  // PE pe finished a task it was handed, taking seconds. Same threading as next().
  virtual void finished(int pe, TaskId task, double seconds) {
    (void)pe, (void)task, (void)seconds;
  }
  // Whether PE pe's answers depend only on reset()'s inputs and pe (a static portion): across
  // ranks, each rank then answers its own PEs; otherwise the system controller on rank 0 holds
  // the strategy and a PE on another rank asks it with a message (rank_stage.cpp).
  virtual bool decidedPerPe() const { return false; }

  // A strategy whose PEs keep local task pools says so, and across ranks each rank runs it for
  // its own PEs [first, first + count) (setLocalPes, before reset), the pools where their PEs
  // are. Without setLocalPes every PE is local - one process, the simulator - and nothing is
  // asked by message; with it, the same decisions, each transfer between ranks a message:
  // - distributed task management (seed 3.4.4): a search for a victim stops at a PE on another
  //   rank with Grab::askPe; that rank's runtime answers with stealFrom(victim), and the
  //   asking PE's runtime hands the tasks (none: the pool was empty) to stolen();
  // - a task manager's local pool (seed 3.4.3) on a rank other than rank 0, where the central
  //   pool is: Grab::refillRequests asks rank 0 for packets ahead of need, answered by
  //   supplyPacket there and handed to refill() here (none: the central pool is exhausted);
  //   an empty pool waits for one (Grab::kAwaitRefill).
  virtual bool localPoolsAcrossRanks() const { return false; }
  virtual void setLocalPes(int first, int count) { (void)first, (void)count; }
  virtual std::vector<TaskId> stealFrom(int victim) {
    (void)victim;
    return {};
  }
  virtual void stolen(int pe, int victim, std::vector<TaskId> tasks) { (void)pe, (void)victim, (void)tasks; }
  virtual std::vector<TaskId> supplyPacket(int pe) {
    (void)pe;
    return {};
  }
  virtual void refill(int pe, std::vector<TaskId> tasks) { (void)pe, (void)tasks; }
};

// Registry: name -> factory -> one-line description, and what the strategy declares about
// itself; feeds --help, validation and reports (common/util/registry.h).
struct ScheduleProperties {
  // The strategy orders or splits tasks by Task::cost, so the caller should estimate costs
  // (a pre-pass or a profile) before the stage; with uniform costs it degenerates.
  bool needsCostEstimates = false;
};
using ScheduleInfo = RegistryEntry<std::unique_ptr<Scheduler> (*)(), ScheduleProperties>;
using ScheduleRegistry = Registry<std::unique_ptr<Scheduler> (*)(), ScheduleProperties>;
const ScheduleRegistry& schedules();
// Throws pr::InputError naming the unknown schedule and listing the valid ones.
std::unique_ptr<Scheduler> makeScheduler(std::string_view name);
bool isSchedule(std::string_view name);
// Whether the named strategy declares that it needs cost estimates; throws pr::InputError
// for an unknown name.
bool scheduleNeedsCostEstimates(std::string_view name);
// "name  description" lines, for --help.
std::string describeSchedules();

// Static splits shared by several strategies (balanced.cpp, unbalanced.cpp; tests check them).
// Balanced: contiguous blocks of ids [0, n), the first n mod P PEs one task more (seed 3.2.1).
std::vector<std::vector<TaskId>> balancedSplit(std::size_t n, int pes);
// Unbalanced: by cost estimate, longest first to the least-loaded PE (ties: lowest PE), each
// PE's list then in image order. Balances to within the largest task of total/P (seed 3.2.1).
std::vector<std::vector<TaskId>> unbalancedSplit(const TaskSet& tasks, int pes);

// Owner-pinned (schedulers/owner_pinned.cpp): task t runs on PE owner[t], sent as one packet
// per PE like a data-driven portion. Not a --schedule choice: the stages whose tasks are tied
// to a PE's data (regions, voxels, per-PE buffers) use it through Runtime::runPinned.
inline constexpr std::string_view kOwnerPinnedSchedule = "owner-pinned";
std::unique_ptr<Scheduler> makeOwnerPinnedScheduler(std::vector<int> owner);
}  // namespace pr::par
