// The farm's master (farm.h): a pool of jobs ordered by a scheduler, one record of who holds
// each job, and a loop that reads results, tops servers up and declares silent servers lost,
// never waiting without a deadline.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <optional>
#include <thread>

#include "common/parallel/farm/farm.h"
#include "common/parallel/farm/farm_messages.h"
#include "common/util/error.h"

namespace pr::par {
namespace {

using Clock = std::chrono::steady_clock;

enum class JobState : std::uint8_t { InPool, Held, Requeued, Done };

struct Server {
  FarmServerRecord record;
  bool hello = false, ready = false;
  std::deque<int> holding;  // jobs sent and not yet done, oldest first
  std::deque<TaskId> granted;  // the rest of a grab of several jobs (--grain)
  bool scheduleDone = false;   // the schedule has nothing more for it
  bool goodbye = false;        // it answered the stop at the end
  double silentSince = 0.0;  // the time from which its silence counts
};

class Master {
 public:
  Master(Transport& transport, const FarmOptions& options, std::uint64_t hash, const TaskSet& jobs, Scheduler& order,
         const ScheduleParams& params)
      : t_(transport),
        options_(options),
        toMaster_(farm::toMasterTag(options.run)),
        toServer_(farm::toServerTag(options.run)),
        hash_(hash),
        order_(order),
        start_(Clock::now()) {
    const int servers = t_.ranks() - 1;
    PR_CHECK(servers >= 1, "a farm needs a server besides the master");
    order_.reset(jobs, servers, params);
    state_.assign(jobs.size(), JobState::InPool);
    holder_.assign(jobs.size(), -1);
    record_.schedule = std::string(order.name());
    record_.prepass = options.sharedPrepass ? "shared" : "replicated";
    record_.deadlineSeconds = options.deadlineSeconds;
    record_.jobsAhead = options.jobsAhead;
    record_.jobs.resize(jobs.size());
    for (std::size_t j = 0; j < jobs.size(); ++j) record_.jobs[j].job = int(j), record_.jobs[j].attempts = 0;
    servers_.resize(std::size_t(servers));
    for (int s = 0; s < servers; ++s) servers_[std::size_t(s)].record.rank = s + 1;
  }

  FarmRecord run(const std::function<void(int, int, std::span<const std::byte>)>& accept,
                 const std::function<void(const FarmProgress&)>& tick, const std::function<void(int)>& lost) {
    lost_ = &lost;
    double nextTick = options_.refreshSeconds;
    // Idle servers hear from the master well within their deadline, whatever the refresh.
    const double keepAlive = std::min(options_.refreshSeconds, options_.deadlineSeconds / 4.0);
    double nextKeepAlive = keepAlive;
    try {
      while (done_ < state_.size()) {
        bool heard = false;
        while (std::optional<Envelope> e = t_.poll(toMaster_)) {
          heard = true;
          handle(*e, accept);
        }
        declareSilentServersLost();
        checkSomeServerLeft();
        const double now = seconds();
        if (now >= nextTick) {
          tick(progress());
          nextTick = now + options_.refreshSeconds;
        }
        if (now >= nextKeepAlive) {
          keepIdleServersWaiting();
          nextKeepAlive = now + keepAlive;
        }
        if (!heard) std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    } catch (...) {
      stopAll(farm::MasterSays::StopFailed);
      throw;
    }
    stopAll(farm::MasterSays::Stop);
    record_.wallSeconds = seconds();
    awaitGoodbyes();
    const FarmProgress last = progress();
    for (Server& s : servers_) record_.servers.push_back(std::move(s.record));
    tick(last);
    return std::move(record_);
  }

 private:
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  Server& server(int rank) { return servers_[std::size_t(rank - 1)]; }

  void handle(const Envelope& e, const std::function<void(int, int, std::span<const std::byte>)>& accept) {
    if (e.source < 1 || e.source >= t_.ranks() || e.bytes.empty()) return;
    Server& s = server(e.source);
    WireReader r(e.bytes);
    const auto kind = r.value<farm::ServerSays>();
    const double now = seconds();
    if (s.record.lost()) {
      // A lost server that woke up: its results are late, anything else it says is moot.
      if (kind == farm::ServerSays::Result) ++s.record.lateResults;
      return;
    }
    s.record.lastHeardSeconds = now;
    s.silentSince = now;
    switch (kind) {
      case farm::ServerSays::Hello: {
        const auto hello = r.value<farm::Hello>();
        s.hello = true;
        s.record.pes = hello.pes;
        if (hello.contentHash != hash_) {
          t_.send(e.source, toServer_, farm::message(farm::MasterSays::Mismatch));
          throw InputError("rank " + std::to_string(e.source) +
                           " loaded a different scene from rank 0's (its content hash differs): every rank must read the same scene");
        }
        // Shared pre-passes start together: every server is welcomed once all have been checked.
        if (!options_.sharedPrepass) {
          t_.send(e.source, toServer_, farm::message(farm::MasterSays::Welcome));
          return;
        }
        if (std::any_of(servers_.begin(), servers_.end(), [](const Server& x) { return !x.hello; })) return;
        for (const Server& x : servers_) t_.send(x.record.rank, toServer_, farm::message(farm::MasterSays::Welcome));
        return;
      }
      case farm::ServerSays::Ready: {
        const auto ready = r.value<farm::Ready>();
        s.ready = true;
        s.record.prepareSeconds = ready.prepareSeconds;
        s.record.prepareMessages = ready.prepareMessages;
        s.record.prepareBytes = ready.prepareBytes;
        topUp(e.source);
        return;
      }
      case farm::ServerSays::Alive:
        return;  // heard above
      case farm::ServerSays::Bye:
        return;  // only after the stop (awaitGoodbyes)
      case farm::ServerSays::Result: {
        const auto h = r.value<farm::ResultHeader>();
        const std::span<const std::byte> result = std::span(e.bytes).subspan(1 + sizeof h);
        const bool counts = h.job >= 0 && std::size_t(h.job) < state_.size() &&
                            state_[std::size_t(h.job)] == JobState::Held && holder_[std::size_t(h.job)] == e.source;
        if (!counts) {
          ++s.record.lateResults;
          return;
        }
        std::erase(s.holding, h.job);
        state_[std::size_t(h.job)] = JobState::Done;
        ++done_;
        FarmJobRecord& j = record_.jobs[std::size_t(h.job)];
        j.server = e.source;
        j.doneSeconds = now;
        j.busySeconds = h.busySeconds;
        j.resultBytes = result.size();
        s.record.jobs.push_back(h.job);
        s.record.busySeconds += h.busySeconds;
        s.record.idleSeconds = h.idleSeconds;
        accept(h.job, e.source, result);
        if (fault_.rank == 0 && fault_.afterJobs == int(done_)) raise(fault_.signal);
        topUp(e.source);
        return;
      }
      case farm::ServerSays::Failed: {
        const auto f = r.value<farm::Failed>();
        throw FarmServerFailed(f.status, "server rank " + std::to_string(e.source) + ": " + farm::textOf(r));
      }
    }
  }

  // The next job for a server: one handed on from a lost server first, then the schedule's,
  // then any job no one has been given yet (in a lost or slow server's static portion, say:
  // the servers that are left do it rather than wait).
  int nextJob(int rank) {
    while (!requeued_.empty()) {
      const int j = requeued_.front();
      requeued_.pop_front();
      if (state_[std::size_t(j)] == JobState::Requeued) return j;
    }
    Server& s = server(rank);
    while (!s.scheduleDone) {
      if (s.granted.empty()) {
        Grab grab;
        order_.next(rank - 1, seconds(), grab);
        if (grab.tasks.empty()) {
          s.scheduleDone = true;  // an empty answer is final
          break;
        }
        s.granted.assign(grab.tasks.begin(), grab.tasks.end());
      }
      const int j = int(s.granted.front());
      s.granted.pop_front();
      if (state_[std::size_t(j)] == JobState::InPool) return j;  // else taken as an orphan already
    }
    for (; orphanScan_ < state_.size(); ++orphanScan_)
      if (state_[orphanScan_] == JobState::InPool) return int(orphanScan_++);
    return -1;
  }

  void topUp(int rank) {
    Server& s = server(rank);
    if (!s.ready || s.record.lost()) return;
    if (s.holding.empty()) s.silentSince = seconds();
    while (int(s.holding.size()) < options_.jobsAhead) {
      const int j = nextJob(rank);
      if (j < 0) return;
      state_[std::size_t(j)] = JobState::Held;
      holder_[std::size_t(j)] = rank;
      FarmJobRecord& jr = record_.jobs[std::size_t(j)];
      jr.sentSeconds = seconds();
      ++jr.attempts;
      s.holding.push_back(j);
      t_.send(rank, toServer_, farm::message(farm::MasterSays::Job, std::int32_t(j)));
    }
  }

  void declareSilentServersLost() {
    const double now = seconds();
    bool handedOn = false;
    for (Server& s : servers_) {
      if (s.record.lost()) continue;
      const bool holdsWork = s.ready && !s.holding.empty();
      const bool preparing = s.hello && !s.ready;
      const bool neverHello = !s.hello && now > options_.readySeconds;
      if (!((holdsWork || preparing) && now - s.silentSince > options_.deadlineSeconds) && !neverHello) continue;
      if (!s.ready && options_.sharedPrepass)
        // The other servers wait in the shared pre-passes for its share: no job can be done.
        throw FarmSharedPrepassLost("farm server rank " + std::to_string(s.record.rank) +
                                    " was lost before its shared pre-passes were done (the other servers need its share of them)");
      s.record.lostAtSeconds = now;
      for (int j : s.holding) {
        state_[std::size_t(j)] = JobState::Requeued;
        holder_[std::size_t(j)] = -1;
        requeued_.push_back(j);
        s.record.handedOn.push_back(j);
      }
      s.holding.clear();
      handedOn = true;
      (*lost_)(s.record.rank);
      // Should it wake up, it finishes the job in hand, sends that (late) result and stops.
      t_.send(s.record.rank, toServer_, farm::message(farm::MasterSays::Stop));
      std::fprintf(stderr, "parrender: farm: server rank %d declared lost after %.1f s of silence%s; %zu job(s) handed on\n",
                   s.record.rank, now - s.silentSince, s.ready ? "" : " (before it was ready)", s.record.handedOn.size());
    }
    if (handedOn)
      for (Server& s : servers_) topUp(s.record.rank);
  }

  // After the stop: every server not lost says goodbye within the deadline. One that does not
  // (it died after its last message, stopped, or is still in its pre-passes) is lost too, so
  // that the run's end does not wait for it.
  void awaitGoodbyes() {
    const double until = seconds() + options_.deadlineSeconds;
    for (;;) {
      while (std::optional<Envelope> e = t_.poll(toMaster_)) {
        if (e->source < 1 || e->source >= t_.ranks() || e->bytes.empty()) continue;
        Server& s = server(e->source);
        const auto kind = farm::ServerSays(e->bytes[0]);
        if (kind == farm::ServerSays::Bye && !s.record.lost()) {
          s.goodbye = true;
          WireReader r(e->bytes);
          (void)r.value<farm::ServerSays>();
          s.record.cpuSeconds = r.value<farm::Bye>().cpuSeconds;
        }
        if (kind == farm::ServerSays::Result) ++s.record.lateResults;
      }
      bool waiting = false;
      for (const Server& s : servers_) waiting = waiting || (!s.record.lost() && !s.goodbye);
      if (!waiting) return;
      if (seconds() > until) break;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    for (Server& s : servers_) {
      if (s.record.lost() || s.goodbye) continue;
      s.record.lostAtSeconds = seconds();
      (*lost_)(s.record.rank);
      std::fprintf(stderr,
                   "parrender: farm: server rank %d declared lost: it did not answer the stop within %.1f s (dead, stopped, or "
                   "still in its pre-passes)\n",
                   s.record.rank, options_.deadlineSeconds);
    }
  }

  void checkSomeServerLeft() {
    for (const Server& s : servers_)
      if (!s.record.lost()) return;
    throw std::runtime_error("every farm server was lost with " + std::to_string(state_.size() - done_) +
                             " job(s) not done");
  }

  // A server that holds no job hears from the master every quarter deadline (or refresh), so it
  // can tell a master that has nothing for it yet from one that is gone.
  void keepIdleServersWaiting() {
    for (Server& s : servers_)
      if (s.hello && !s.record.lost() && s.holding.empty())
        t_.send(s.record.rank, toServer_, farm::message(farm::MasterSays::Wait));
  }

  void stopAll(farm::MasterSays how) {
    for (const Server& s : servers_) t_.send(s.record.rank, toServer_, farm::message(how));
  }

  FarmProgress progress() const {
    FarmProgress p;
    p.jobsDone = int(done_);
    p.jobs = int(state_.size());
    p.seconds = seconds();
    for (const Server& s : servers_) {
      if (s.record.lost())
        p.lostRanks.push_back(s.record.rank);
      else if (s.ready)
        ++p.serversWorking;
      else
        ++p.serversPreparing;
    }
    return p;
  }

  Transport& t_;
  FarmOptions options_;
  int toMaster_, toServer_;
  std::uint64_t hash_;
  Scheduler& order_;
  Clock::time_point start_;
  std::vector<JobState> state_;
  std::vector<int> holder_;
  std::vector<Server> servers_;
  std::deque<int> requeued_;
  std::size_t done_ = 0, orphanScan_ = 0;
  const std::function<void(int)>* lost_ = nullptr;
  FarmFault fault_ = farmFaultFromEnvironment();
  FarmRecord record_;
};

}  // namespace

FarmRecord runFarmMaster(Transport& transport, const FarmOptions& options, std::uint64_t contentHash,
                         const TaskSet& jobs, Scheduler& order, const ScheduleParams& params,
                         const std::function<void(int, int, std::span<const std::byte>)>& accept,
                         const std::function<void(const FarmProgress&)>& tick, const std::function<void(int)>& lost) {
  Master master(transport, options, contentHash, jobs, order, params);
  return master.run(accept, tick, lost);
}

}  // namespace pr::par
