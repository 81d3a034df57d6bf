// A farm server (farm.h): hello, pre-passes, then jobs as they come, each result sent back and
// flushed before the next job starts (a large result moves only while this rank is inside MPI).
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <string>
#include <thread>

#include "common/parallel/farm/farm.h"
#include "common/parallel/farm/farm_messages.h"
#include "common/parallel/runtime.h"
#include "common/util/cpu_time.h"
#include "common/util/error.h"

namespace pr::par {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string formatSeconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}

class Server {
 public:
  Server(Transport& t, const FarmOptions& options)
      : t_(t), options_(options), toMaster_(farm::toMasterTag(options.run)), toServer_(farm::toServerTag(options.run)) {}

  // The next message from the master, waiting at most `seconds` (the master writes to a
  // server that waits at least every quarter deadline; a job in hand is not a wait).
  Envelope await(double seconds, const char* what) {
    const Clock::time_point from = Clock::now();
    for (;;) {
      if (std::optional<Envelope> e = t_.poll(toServer_)) return std::move(*e);
      if (since(from) > seconds) masterLost("sent nothing for " + formatSeconds(seconds) + " while this server waited for " + what);
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }

  // Files the master's message; false when it says stop.
  bool take(const Envelope& e) {
    WireReader r(e.bytes);
    switch (r.value<farm::MasterSays>()) {
      case farm::MasterSays::Job:
        jobs_.push_back(r.value<std::int32_t>());
        return true;
      case farm::MasterSays::Wait:
      case farm::MasterSays::Welcome:
        return true;
      case farm::MasterSays::Mismatch:
        throw InputError("");  // rank 0 says which rank's scene differs
      case farm::MasterSays::StopFailed:
        throw FailedElsewhere("the farm stopped after a failure on another rank");
      case farm::MasterSays::Stop:
        return false;
    }
    return true;
  }

  void send(const Bytes& b) { t_.send(0, toMaster_, b); }
  void flush() {
    if (!t_.flush(options_.deadlineSeconds))
      masterLost("took no result for " + formatSeconds(options_.deadlineSeconds));
  }

  // The master is gone or hung: nothing this server does can reach the user, and the ending
  // protocol would wait for the master too, so the server ends every rank at once.
  [[noreturn]] void masterLost(const std::string& how) {
    std::fprintf(stderr, "parrender: failed (rank %d of %d): the farm's master (rank 0) %s; ending every rank\n", t_.rank(),
                 t_.ranks(), how.c_str());
    t_.abortAll(1);
    std::_Exit(1);  // abortAll does not return; the compiler cannot see that through the virtual call
  }

  Transport& t_;
  FarmOptions options_;
  int toMaster_, toServer_;
  std::deque<int> jobs_;
};

// Raises the test fault as the server starts a job, having sent `sent` results.
void injectFault(const FarmFault& fault, int rank, int sent) {
  if (fault.rank != rank || fault.afterJobs != sent) return;
  if (!fault.pidFile.empty()) std::ofstream(fault.pidFile) << getpid() << "\n";
  raise(fault.signal);
}

// Runs work() while a thread tells the master every quarter deadline that this server is alive:
// pre-passes and jobs may take far longer than the deadline, which is for servers that die or
// stop (a stopped process stops this thread too), not for slow ones.
template <class Work>
auto alive(Server& s, const Work& work) -> decltype(work()) {
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  const auto every = std::chrono::duration<double>(s.options_.deadlineSeconds / 4.0);
  std::thread heartbeat([&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (!finished.wait_for(lock, every, [&] { return done; })) s.send(farm::message(farm::ServerSays::Alive));
  });
  const auto stop = [&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
    }
    finished.notify_one();
    heartbeat.join();
  };
  try {
    auto result = work();
    stop();
    return result;
  } catch (...) {
    stop();
    throw;
  }
}

}  // namespace

FarmFault farmFaultFromEnvironment() {
  FarmFault f;
  const char* v = std::getenv("PARRENDER_FARM_FAULT");
  if (!v || !*v) return f;
  const std::string text(v);
  char pid[512] = {};
  const int n = std::sscanf(v, "%d:%d:%d:%511s", &f.rank, &f.afterJobs, &f.signal, pid);
  if (n < 3 || f.rank < 0 || f.afterJobs < -1 || f.signal <= 0 || f.signal >= 32)
    throw InputError("PARRENDER_FARM_FAULT must be RANK:JOBS:SIGNAL[:PIDFILE] with RANK >= 0, not '" + text + "'");
  if (n == 4) f.pidFile = pid;
  return f;
}

void runFarmServer(Transport& transport, const FarmOptions& options, std::uint64_t contentHash, int pes,
                   const std::function<PrepareTraffic()>& prepare, const std::function<Bytes(int)>& work) {
  const FarmFault fault = farmFaultFromEnvironment();
  Server s(transport, options);
  const auto failed = [&](int status, const std::string& text) {
    s.send(farm::message(farm::ServerSays::Failed, farm::Failed{status},
                         std::as_bytes(std::span<const char>(text.data(), text.size()))));
    (void)transport.flush(options.deadlineSeconds);
  };
  const double cpuAtHello = processCpuSeconds();
  s.send(farm::message(farm::ServerSays::Hello, farm::Hello{contentHash, pes, 0}));
  // Told to stop: it says so, so the master knows it is not waiting for a lost rank.
  const auto leave = [&] {
    s.send(farm::message(farm::ServerSays::Bye, farm::Bye{processCpuSeconds() - cpuAtHello}));
    (void)transport.flush(options.deadlineSeconds);
  };
  for (;;) {  // the welcome (a master sharing the pre-passes welcomes every server at once)
    const Envelope e = s.await(options.readySeconds, "its welcome");
    if (!e.bytes.empty() && farm::MasterSays(e.bytes[0]) == farm::MasterSays::Wait) continue;
    if (!s.take(e)) return leave();
    break;
  }
  double idle = 0.0;
  int sent = 0;
  try {
    const Clock::time_point started = Clock::now();
    injectFault(fault, transport.rank(), -1);
    const PrepareTraffic traffic = alive(s, prepare);
    s.send(farm::message(farm::ServerSays::Ready, farm::Ready{since(started), traffic.messages, traffic.bytes}));
    for (;;) {
      // Every message already here first: a stop, or the next jobs.
      while (std::optional<Envelope> e = transport.poll(s.toServer_))
        if (!s.take(*e)) return leave();
      if (s.jobs_.empty()) {
        const Clock::time_point waiting = Clock::now();
        const bool more = s.take(s.await(options.deadlineSeconds, "a job"));
        idle += since(waiting);
        if (!more) return leave();
        continue;
      }
      const int job = s.jobs_.front();
      s.jobs_.pop_front();
      injectFault(fault, transport.rank(), sent);
      const Clock::time_point begun = Clock::now();
      const Bytes result = alive(s, [&] { return work(job); });
      const farm::ResultHeader header{since(begun), idle, job};
      s.send(farm::message(farm::ServerSays::Result, header, result));
      s.flush();
      ++sent;
    }
  } catch (const FailedElsewhere&) {
    throw;
  } catch (const InputError& e) {
    failed(kExitBadInput, e.what());
    throw;
  } catch (const std::exception& e) {
    failed(1, e.what());
    throw;
  }
}

}  // namespace pr::par
