// The thread engine: one std::thread per PE for the runtime's life, a Scheduler shared by all of
// them in each stage, counters per PE, and the end-of-stage bookkeeping that turns counters into
// a StageRecord.
// Sits between the renderers' stages and metrics.cpp (seed chapter 3, task management).
#include "common/parallel/runtime.h"

#include <algorithm>
#include <condition_variable>
#include <thread>

#include "common/parallel/cell_split.h"
#include "common/util/error.h"

namespace pr::par {

// Where an idle PE blocks until a message arrives for it or the stage ends. `rung` is set
// under the mutex after every enqueue, so a message sent between the PE's last poll and its
// wait is never missed.
struct Runtime::Doorbell {
  std::mutex mutex;
  std::condition_variable cv;
  bool rung = false;
};

Runtime::Runtime(RuntimeOptions options) : options_(std::move(options)), epoch_(std::chrono::steady_clock::now()) {
  if (options_.pes < 1 || options_.pes > 4096)
    throw InputError("number of PEs must be in [1, 4096], got " + std::to_string(options_.pes));
  if (options_.params.grain < 1)
    throw InputError("grain must be at least 1 task, got " + std::to_string(options_.params.grain));
  schedule_ = makeScheduler(options_.schedule);
  const int p = options_.pes;
  if (options_.transport && options_.transport->ranks() > 1) {
    ranks_ = options_.transport->ranks();
    rank_ = options_.transport->rank();
    if (p % ranks_ != 0)
      throw InputError(std::to_string(p) + " PEs cannot be spread evenly over " + std::to_string(ranks_) + " ranks");
  }
  localPes_ = p / ranks_;
  rankStage_.answers.resize(static_cast<std::size_t>(localPes_));
  counters_ = std::vector<PeCounters>(p);
  pairMessages_ = std::vector<std::atomic<std::uint64_t>>(static_cast<std::size_t>(p) * p);
  pairBytes_ = std::vector<std::atomic<std::uint64_t>>(static_cast<std::size_t>(p) * p);
  for (int i = 0; i < p; ++i) bells_.push_back(std::make_unique<Doorbell>());
  spans_.resize(p);
  cells_.resize(p);
  record_.pes = p;
  record_.ranks = ranks_;
  record_.schedule = options_.schedule;
  record_.grain = options_.params.grain;
}

Runtime::~Runtime() {
  {
    std::lock_guard lock(stageMutex_);
    shutdown_ = true;
  }
  stageStart_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void Runtime::startWorkers() {
  workers_.reserve(localPes_);
  for (int p = firstLocalPe(); p < firstLocalPe() + localPes_; ++p) workers_.emplace_back([this, p] { workerMain(p); });
}

namespace {

// Polls ready() with yields for a few tens of microseconds before the caller blocks: stages of a
// raster frame follow each other within microseconds, and a futex wake-up costs more than that.
template <class Ready>
void spinBriefly(Ready&& ready) {
  for (int i = 0; i < 256 && !ready(); ++i) std::this_thread::yield();
}

}  // namespace

// A PE thread: waits for the next stage, runs its share, reports back; until the runtime ends.
void Runtime::workerMain(int p) {
  std::uint64_t seen = 0;
  for (;;) {
    StageJob job;
    spinBriefly([&] { return generation_.load(std::memory_order_acquire) != seen; });
    {
      std::unique_lock lock(stageMutex_);
      stageStart_.wait(lock, [&] { return shutdown_ || generation_ != seen; });
      if (shutdown_) return;
      seen = generation_;
      job = job_;
    }
    peLoop(p, job);
    {
      std::lock_guard lock(stageMutex_);
      if (--running_ == 0) stageDone_.notify_one();
    }
  }
}

void Runtime::runStage(std::string_view name, const TaskSet& tasks, const TaskFn& work) {
  runStage(name, tasks, *schedule_, work);
}

void Runtime::runStage(std::string_view name, const TaskSet& tasks, const SetupFn& setup, const TaskFn& work) {
  runStage(name, tasks, *schedule_, &setup, work, {});
}

void Runtime::runPinned(std::string_view name, const TaskSet& tasks, std::vector<int> owner, const TaskFn& work) {
  const std::unique_ptr<Scheduler> pinned = makeOwnerPinnedScheduler(owner);
  runStage(name, tasks, *pinned, nullptr, work, std::move(owner));
}

void Runtime::runOnEachPe(std::string_view name, const std::function<void(Pe&)>& work) {
  std::vector<int> owner(static_cast<std::size_t>(options_.pes));
  for (int p = 0; p < options_.pes; ++p) owner[static_cast<std::size_t>(p)] = p;
  const TaskSet tasks = TaskSet::uniform(owner.size());
  runPinned(name, tasks, std::move(owner), [&](Pe& pe, TaskId t) {
    PR_CHECK(t == pe.id(), "task " + std::to_string(t) + " of each-PE stage '" + pe.stageName() + "' ran on PE " +
                               std::to_string(pe.id()));
    work(pe);
  });
  record_.stages.back().kind = kEachPeStage;
}

void Runtime::runOnEachPeInFull(std::string_view name, const std::function<void(Pe&)>& work) {
  runOnEachPe(name, work);
  record_.stages.back().kind = kEachPeInFullStage;
}

void Runtime::runOncePerRank(std::string_view name, const std::function<void(Pe&)>& work) {
  std::vector<int> owner;
  for (int r = 0; r < ranks_; ++r) owner.push_back(r * localPes_);
  const TaskSet tasks = TaskSet::uniform(owner.size());
  runPinned(name, tasks, std::move(owner), [&](Pe& p, TaskId) { work(p); });
  record_.stages.back().kind = kOnePeStage;
}

void Runtime::runOnOnePe(std::string_view name, int pe, const std::function<void(Pe&)>& work) {
  runPinned(name, TaskSet::uniform(1), {pe}, [&](Pe& p, TaskId) { work(p); });
  record_.stages.back().kind = kOnePeStage;
}

void Runtime::recordBroadcast(std::size_t bytes, int root) {
  PR_CHECK(!inStage_, "recordBroadcast is called between stages");
  PR_CHECK(root >= 0 && root < options_.pes, "broadcast root out of range");
  pendingBroadcasts_.push_back({bytes, root});
}

void Runtime::recordBroadcastWithinRanks(std::size_t bytes) {
  PR_CHECK(!inStage_, "recordBroadcastWithinRanks is called between stages");
  pendingBroadcasts_.push_back({bytes, 0, PendingBroadcast::To::WithinRanks});
}

void Runtime::recordReplicated(std::size_t bytes) {
  PR_CHECK(!inStage_, "recordReplicated is called between stages");
  pendingBroadcasts_.push_back({bytes, 0, PendingBroadcast::To::WithinRanksReplicated});
}

void Runtime::recordCell(const Pe& pe, int cell, double seconds, std::uint64_t resultBytes) {
  PR_CHECK(cell >= kCollectCell, "recordCell: cell " + std::to_string(cell));
  if (options_.recordTimeline) cells_[pe.id()].push_back({pe.id(), pe.stage(), cell, std::max(0.0, seconds), resultBytes});
}

void Runtime::describeCells(std::string_view split, int cells, int collector) {
  PR_CHECK(!inStage_ && !record_.stages.empty(), "describeCells is called after the stage it describes");
  PR_CHECK(isCellSplit(split), "describeCells: unknown split '" + std::string(split) + "'");
  PR_CHECK(cells > 0 && collector >= -1 && collector < options_.pes,
           "describeCells: " + std::to_string(cells) + " cells, collector " + std::to_string(collector));
  StageRecord& stage = record_.stages.back();
  stage.cellSplit = std::string(split);
  stage.cellCount = cells;
  stage.cellCollector = collector;
  for (std::size_t i = lastStageCells_; i < record_.cells.size(); ++i)
    PR_CHECK(record_.cells[i].cell < cells && (record_.cells[i].cell != kCollectCell || record_.cells[i].pe == collector),
             "describeCells: cell " + std::to_string(record_.cells[i].cell) + " of " + std::to_string(cells) + " on PE " +
                 std::to_string(record_.cells[i].pe));
}

void Runtime::addCounter(std::string_view name, int pe, double value) {
  PR_CHECK(pe >= 0 && pe < options_.pes, "counter '" + std::string(name) + "' names PE " + std::to_string(pe));
  std::lock_guard<std::mutex> lock(counterMutex_);
  auto it = std::find_if(record_.counters.begin(), record_.counters.end(),
                         [&](const CounterRecord& c) { return c.name == name; });
  if (it == record_.counters.end())
    it = record_.counters.insert(record_.counters.end(),
                                 CounterRecord{std::string(name), std::vector<double>(options_.pes, 0.0)});
  it->perPe[pe] += value;
}

std::string_view toString(MessageKind kind) {
  switch (kind) {
    case MessageKind::Primitives: return "primitives";
    case MessageKind::Pixels: return "pixels";
    case MessageKind::Rays: return "rays";
    case MessageKind::Results: return "results";
    case MessageKind::Requests: return "requests";
    case MessageKind::Data: return "data";
  }
  return "?";
}

void Runtime::attach(ChannelBase* channel, bool handled) {
  PR_CHECK(!inStage_, "channels are created between stages");
  std::lock_guard lock(channelMutex_);
  channel->setId(static_cast<std::uint32_t>(channelsById_.size()));
  channelsById_.push_back(channel);
  registered_.push_back(channel);
  if (handled) channels_.push_back(channel);
}

void Runtime::detach(ChannelBase* channel) {
  PR_CHECK(!inStage_, "channels are destroyed between stages");
  std::lock_guard lock(channelMutex_);
  channelsById_[channel->id()] = nullptr;
  channels_.erase(std::remove(channels_.begin(), channels_.end(), channel), channels_.end());
  registered_.erase(std::remove(registered_.begin(), registered_.end(), channel), registered_.end());
}

void Runtime::countMessage(int from, int to, std::size_t bytes) {
  PR_CHECK(inStage_, "messages are sent by PEs inside a stage");
  if (from == to) return;  // not a transfer between PEs
  const std::size_t pair = static_cast<std::size_t>(from) * options_.pes + to;
  pairMessages_[pair].fetch_add(1, std::memory_order_relaxed);
  pairBytes_[pair].fetch_add(bytes, std::memory_order_relaxed);
  counters_[from].messagesSent.fetch_add(1, std::memory_order_relaxed);
  counters_[from].bytesSent.fetch_add(bytes, std::memory_order_relaxed);
  if (isLocal(to)) countReceived(to, bytes);
}

void Runtime::countReceived(int to, std::size_t bytes) {
  counters_[to].messagesReceived.fetch_add(1, std::memory_order_relaxed);
  counters_[to].bytesReceived.fetch_add(bytes, std::memory_order_relaxed);
}

void Runtime::ring(int pe) {
  Doorbell& bell = *bells_[pe];
  {
    std::lock_guard lock(bell.mutex);
    bell.rung = true;
  }
  bell.cv.notify_one();
}

void Runtime::ringAll() {
  for (int p = firstLocalPe(); p < firstLocalPe() + localPes_; ++p) ring(p);
}

void Runtime::fail(int p, const std::string& stage, TaskId task, std::exception_ptr error) {
  {
    std::lock_guard lock(errorMutex_);
    if (!error_) {
      error_ = error;
      rankStage_.failedHere = true;
      std::string what = "unknown exception";
      try {
        std::rethrow_exception(error);
      } catch (const std::exception& e) {
        what = e.what();
      } catch (...) {
      }
      record_.error = "stage '" + stage + "', PE " + std::to_string(p) +
                      (task == kMessageSpan ? ", message handler"
                       : task == kSetupSpan ? ", set-up"
                                            : ", task " + std::to_string(task)) +
                      ": " + what;
    }
  }
  abort_.store(true, std::memory_order_release);
  ringAll();
}

// A PE with no task left blocks here until a message arrives or the stage's work is done. Whether
// the wait was for a message or at the closing barrier is known only afterwards: the wait is
// kept pending, booked as message waiting when more work follows (confirmWait), and left as
// barrier time (syncWaitSeconds) when nothing does.
void Runtime::waitForWork(int p) {
  Doorbell& bell = *bells_[p];
  const double t0 = now();
  {
    std::unique_lock lock(bell.mutex);
    bell.cv.wait(lock, [&] { return bell.rung || stageOver() || abort_.load(std::memory_order_acquire); });
    bell.rung = false;
  }
  counters_[p].pendingWaitSeconds += now() - t0;
}

void Runtime::confirmWait(PeCounters& c) {
  c.messageWaitSeconds += c.pendingWaitSeconds;
  c.pendingWaitSeconds = 0.0;
}

// Runs work() as one timed piece of the PE's work (a task, a message handler or its set-up):
// busy time less any wait for a reply inside it, and a span with the data messages it sent.
// work returns false when it did nothing (no message after all): nothing is booked then.
// Returns the piece's seconds, or nothing when it did nothing.
template <class Work>
std::optional<double> Runtime::timed(Pe& pe, TaskId task, std::vector<TaskSpan>& spans, Work&& work) {
  PeCounters& c = pe.counters();
  const std::uint64_t m0 = c.messagesSent.load(std::memory_order_relaxed);
  const std::uint64_t b0 = c.bytesSent.load(std::memory_order_relaxed);
  const double t0 = now();
  confirmWait(c);
  const double w0 = c.inTaskWaitSeconds;
  if (!work()) return std::nullopt;
  const double t1 = now();
  const double waited = c.inTaskWaitSeconds - w0;
  c.busySeconds += (t1 - t0) - waited;
  c.lastWorkEnd = t1;
  if (options_.recordTimeline)
    spans.push_back({pe.id(), pe.stage(), task, t0, t1,
                     static_cast<std::uint32_t>(c.messagesSent.load(std::memory_order_relaxed) - m0),
                     c.bytesSent.load(std::memory_order_relaxed) - b0, waited});
  return t1 - t0;
}

bool Runtime::serveOne(Pe& pe) {
  PR_CHECK(inStage_, "serveOne is called by a PE inside a task");
  // channels_ changes only between stages, so a stage reads it without the lock. Requests
  // first: another PE may be blocked on the answer, where a result (a finished region) can wait.
  for (const bool requests : {true, false})
    for (ChannelBase* channel : channels_)
      if ((channel->kind() == MessageKind::Requests) == requests && channel->pending(pe.id()) && channel->handleOne(pe)) {
        pe.counters().messagesHandled.fetch_add(1, std::memory_order_relaxed);
        outstanding_.done();  // the waiting task is still counted, so never the last unit
        return true;
      }
  return false;
}

// Handles every message waiting for pe in the handled channels; true when it handled any.
bool Runtime::handleMessages(Pe& pe, std::vector<TaskSpan>& spans) {
  bool any = false;
  for (ChannelBase* channel : channels_) {
    while (channel->pending(pe.id()) && !abort_.load(std::memory_order_relaxed)) {
      if (!timed(pe, kMessageSpan, spans, [&] { return channel->handleOne(pe); })) break;
      pe.counters().messagesHandled.fetch_add(1, std::memory_order_relaxed);
      any = true;
      if (outstanding_.done()) ringAll();
    }
  }
  return any;
}

// The loop of one PE for one stage: its set-up if the stage has one; then messages first (they
// unblock other PEs), then the next task(s) from the scheduler, then wait until a message
// arrives or the stage's work is done.
void Runtime::peLoop(int p, const StageJob& job) {
  Scheduler& scheduler = *job.scheduler;
  const TaskFn& work = *job.work;
  const int stage = job.stage;
  const std::string& name = *job.name;
  PeCounters& c = counters_[p];
  Pe pe(*this, p, options_.pes, stage, name, c);
  std::vector<TaskSpan>& spans = spans_[p];
  Grab grab;
  bool tasksLeft = true;
  TaskId current = kSetupSpan;
  // Across ranks a PE is outstanding work until it knows it has no task left (its tasks are
  // not known to its rank in advance); on one rank every task is counted from the start.
  const bool acrossRanks = ranks_ > 1;
  const bool askController =
      acrossRanks && rank_ != 0 && !scheduler.decidedPerPe() && !scheduler.localPoolsAcrossRanks();
  std::vector<TaskReport> reports;  // finished tasks, for the controller's next answer
  bool asked = false;               // a request to the controller is in flight
  try {
    if (job.setup && *job.setup && !abort_.load(std::memory_order_acquire)) {
      // Messages that arrive meanwhile wait in their channels.
      timed(pe, kSetupSpan, spans, [&] {
        (*job.setup)(pe);
        return true;
      });
      if (outstanding_.done()) ringAll();
    }
    while (!abort_.load(std::memory_order_acquire)) {
      current = kMessageSpan;
      if (handleMessages(pe, spans)) continue;
      if (tasksLeft) {
        nextTasks(pe, scheduler, askController, grab, spans, reports, asked);
        // Asked of rank 0's controller, and answered, by messages between ranks; a search that
        // found no task still sent its requests (a work-stealing PE's last).
        if (grab.from != p) bookScheduling(p, std::uint64_t(grab.requests + grab.packets), grab.transferBytes(), askController);
        if (grab.tasks.empty()) {
          tasksLeft = false;
          if (acrossRanks) outstanding_.done();
          continue;
        }
        for (TaskId id : grab.tasks) {
          if (abort_.load(std::memory_order_relaxed)) break;
          current = id;
          const double seconds = *timed(pe, id, spans, [&] {
            work(pe, id);
            return true;
          });
          c.tasks.fetch_add(1, std::memory_order_relaxed);
          if (askController) {
            reports.push_back({id, seconds});
          } else {
            scheduler.finished(p, id, seconds);
          }
          if (!acrossRanks && outstanding_.done()) ringAll();
          if (acrossRanks) pumpRankStage();  // messages move between tasks too
          current = kMessageSpan;
          handleMessages(pe, spans);
        }
        continue;
      }
      if (stageOver()) break;
      waitForWork(p);
    }
  } catch (...) {
    fail(p, name, current, std::current_exception());
  }
}

void Runtime::runStage(std::string_view name, const TaskSet& tasks, Scheduler& scheduler, const TaskFn& work) {
  runStage(name, tasks, scheduler, nullptr, work, {});
}

void Runtime::runStage(std::string_view nameView, const TaskSet& tasks, Scheduler& scheduler, const SetupFn* setup,
                       const TaskFn& work, std::vector<int> owners) {
  PR_CHECK(!inStage_, "runStage is called by the controlling thread, not from inside a stage");
  if (rankStage_.spent) throw std::runtime_error("the runtime stopped after a failure on one of its ranks");
  const int pes = options_.pes;
  const std::string name(nameView);
  const int stage = static_cast<int>(record_.stages.size());

  // Reset the live state; no PE thread exists at this point.
  for (PeCounters& c : counters_) {
    for (auto* a : {&c.tasks, &c.messagesHandled, &c.messagesSent, &c.bytesSent, &c.messagesReceived,
                    &c.bytesReceived, &c.schedulingMessages, &c.schedulingBytes, &c.schedulingMessagesBetweenRanks,
                    &c.schedulingBytesBetweenRanks, &c.cacheHits, &c.cacheMisses, &c.prefetches})
      a->store(0, std::memory_order_relaxed);
    c.busySeconds = c.sendReceiveSeconds = c.messageWaitSeconds = c.inTaskWaitSeconds = c.pendingWaitSeconds = 0.0;
  }
  for (auto& a : pairMessages_) a.store(0, std::memory_order_relaxed);
  for (auto& a : pairBytes_) a.store(0, std::memory_order_relaxed);
  for (auto& bell : bells_) bell->rung = false;
  for (auto& s : spans_) s.clear();
  for (auto& c : cells_) c.clear();
  abort_.store(false);
  error_ = nullptr;
  // Every task and every PE's set-up is outstanding work until it returns (termination.h);
  // across ranks, every local PE until it has no task left, and every local set-up.
  const bool hasSetup = setup && *setup;
  if (ranks_ == 1)
    outstanding_.reset(static_cast<std::int64_t>(tasks.size()) + (hasSetup ? pes : 0));
  else
    outstanding_.reset(localPes_ + (hasSetup ? localPes_ : 0));
  rankStage_.over.store(false);
  rankStage_.sent.store(0);
  rankStage_.received.store(0);
  rankStage_.failedHere = rankStage_.announced = false;
  for (std::optional<Grab>& answer : rankStage_.answers) answer.reset();
  if (ranks_ > 1) scheduler.setLocalPes(firstLocalPe(), localPes_);  // local pools where their PEs are
  scheduler.reset(tasks, pes, options_.params);

  if (workers_.empty()) startWorkers();
  inStage_ = true;
  const double start = now();
  for (PeCounters& c : counters_) c.lastWorkEnd = start;
  {
    std::unique_lock lock(stageMutex_);
    job_ = StageJob{&scheduler, &work, setup, stage, &name};
    running_ = localPes_;
    ++generation_;
  }
  stageStart_.notify_all();
  if (ranks_ > 1) {
    try {
      driveRankStage(stage);
    } catch (...) {  // a message that breaks the protocol: this rank's failure
      fail(firstLocalPe(), name, kMessageSpan, std::current_exception());
      rankStage_.spent = true;
    }
  }
  spinBriefly([&] { return running_.load(std::memory_order_acquire) == 0; });
  {
    std::unique_lock lock(stageMutex_);
    stageDone_.wait(lock, [&] { return running_ == 0; });
  }
  const double end = now();
  inStage_ = false;

  // The StageRecord: idle = wall - busy; the wait at the closing barrier is the time after the
  // PE's last piece of work.
  StageRecord sr;
  sr.name = name;
  sr.schedule = std::string(scheduler.name());
  sr.grain = options_.params.grain;
  sr.startSeconds = start;
  sr.wallSeconds = end - start;
  sr.tasks = tasks.tasks;
  sr.owners = std::move(owners);
  sr.pes.resize(pes);
  for (int p = 0; p < pes; ++p) {
    const PeCounters& c = counters_[p];
    PeStageRecord& r = sr.pes[p];
    r.busySeconds = c.busySeconds;
    r.idleSeconds = std::max(0.0, sr.wallSeconds - c.busySeconds);
    r.syncWaitSeconds = std::max(0.0, end - std::max(c.lastWorkEnd, start));
    r.sendReceiveSeconds = c.sendReceiveSeconds;
    r.messageWaitSeconds = c.messageWaitSeconds;
    r.tasks = c.tasks.load();
    r.messagesHandled = c.messagesHandled.load();
    r.messagesSent = c.messagesSent.load();
    r.bytesSent = c.bytesSent.load();
    r.messagesReceived = c.messagesReceived.load();
    r.bytesReceived = c.bytesReceived.load();
    r.schedulingMessages = c.schedulingMessages.load();
    r.schedulingBytes = c.schedulingBytes.load();
    r.schedulingMessagesBetweenRanks = c.schedulingMessagesBetweenRanks.load();
    r.schedulingBytesBetweenRanks = c.schedulingBytesBetweenRanks.load();
    const bool firstOfRank = p % localPes_ == 0, firstOfOtherRank = firstOfRank && p / localPes_ != 0;
    using To = PendingBroadcast::To;
    for (const PendingBroadcast& b : pendingBroadcasts_) {
      const bool within = b.to == To::WithinRanks || b.to == To::WithinRanksReplicated;
      if (b.to == To::OtherRanksFirstPe ? firstOfOtherRank : within ? !firstOfRank : b.root != p) {
        r.broadcastsReceived += 1;
        r.broadcastBytesReceived += b.bytes;
      } else if (b.to == To::WithinRanksReplicated && firstOfOtherRank) {
        r.replicatedCopies += 1;
        r.replicatedBytes += b.bytes;
      }
    }
    r.cacheHits = c.cacheHits.load();
    r.cacheMisses = c.cacheMisses.load();
    r.prefetches = c.prefetches.load();
    for (int q = 0; q < pes; ++q) {
      const std::size_t pair = static_cast<std::size_t>(p) * pes + q;
      if (pairMessages_[pair].load() > 0) sr.traffic.push_back({p, q, pairMessages_[pair].load(), pairBytes_[pair].load()});
    }
  }
  {
    std::lock_guard lock(channelMutex_);
    for (ChannelBase* channel : registered_) {
      const auto [messages, bytes, remoteMessages, remoteBytes] = channel->takeCounts();
      if (messages > 0)
        sr.channels.push_back({channel->name(), std::string(toString(channel->kind())), messages, bytes, remoteMessages, remoteBytes});
    }
  }
  for (const PendingBroadcast& b : pendingBroadcasts_) {
    sr.broadcasts += 1;
    sr.broadcastBytes += b.bytes;
  }
  pendingBroadcasts_.clear();
  record_.stages.push_back(std::move(sr));
  for (auto& s : spans_) record_.timeline.insert(record_.timeline.end(), s.begin(), s.end());
  lastStageCells_ = record_.cells.size();
  for (auto& c : cells_) record_.cells.insert(record_.cells.end(), c.begin(), c.end());
  record_.wallSeconds = end - record_.stages.front().startSeconds;

  if (error_) std::rethrow_exception(error_);
}

}  // namespace pr::par
