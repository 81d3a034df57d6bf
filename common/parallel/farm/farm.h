// The farm (Jensen's photon-map render farm, seed section 3's demand-driven model across
// machines): rank 0, the master, holds a pool of jobs and hands them out on demand to the
// servers, every other rank; each server holds all the data a job needs, does its jobs with its
// own PEs and sends each result back. Unlike the runtime across processes (runtime.h), whose SPMD
// stages end by collective termination that a dead rank would block, the farm is point to point
// with deadlines, so it survives servers that die or stop answering:
// - a server that holds jobs and has sent nothing for deadlineSeconds is declared lost (a working
//   server says it is alive every quarter deadline, however long its job), and the
//   jobs it held go to the others first; it is sent nothing more;
// - a result counts only from the server that holds its job now: a lost server that wakes up
//   and sends late results has them discarded by job, never added twice;
// - the master never waits for a silent server without a deadline, and a server that hears
//   nothing from the master for deadlineSeconds (the master keeps idle servers told to wait)
//   ends the run. The deadline tells dead and stopped processes from working ones; a job that
//   never ends inside a live process (its PEs hung) keeps its server alive and is not caught.
// The transport must tolerate lost ranks (Transport::tolerateLostRanks) and the run must be
// launched with `mpirun --enable-recovery`, or a dead server takes every rank with it.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/parallel/farm/farm_record.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/task.h"
#include "common/parallel/transport.h"

namespace pr::par {

// A job message's size: its kind and the job's id (farm_messages.h).
inline constexpr std::size_t kFarmJobBytes = 1 + sizeof(std::int32_t);

struct FarmOptions {
  double deadlineSeconds = 30.0;  // a server holding jobs that sends nothing this long is lost
  int jobsAhead = 2;              // jobs a server holds at once: one in work, the next ones already there
  double refreshSeconds = 2.0;    // how often the master reports progress (and keeps idle servers waiting)
  double readySeconds = 300.0;    // how long a server may take to load the scene and say hello
  // The servers' pre-passes are one computation shared among them (each traces its share, the
  // results all-gathered): a server lost before it is ready then ends every rank at once,
  // since the others wait for its share. Otherwise each server's pre-passes are its own.
  bool sharedPrepass = false;
  // Which farm run of the command this is, counted alike on every rank (compare runs several):
  // each run's messages go on tags of their own (farm_messages.h).
  int run = 0;
};

// What a server's pre-passes sent to other servers (shared pre-passes; zero otherwise).
struct PrepareTraffic {
  std::uint64_t messages = 0, bytes = 0;
};

// The master's view at a progress tick.
struct FarmProgress {
  int jobsDone = 0, jobs = 0;
  int serversWorking = 0;    // ready and not lost
  int serversPreparing = 0;  // not ready yet
  std::vector<int> lostRanks;
  double seconds = 0.0;  // since the farm began
};

// A server lost before its shared pre-passes were done (FarmOptions::sharedPrepass): the other
// servers wait inside the pre-passes for its share and cannot be told to stop, so the caller
// must end every rank (ProcessGroup::abortRun).
class FarmSharedPrepassLost : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A server's failure, reported to the master (status: the exit status, 2 for bad input).
class FarmServerFailed : public std::runtime_error {
 public:
  FarmServerFailed(int status, const std::string& what) : std::runtime_error(what), status(status) {}
  int status;
};

// On rank 0: hands out jobs [0, jobs.size()) in the order `order` gives them (reset with one PE
// per server, server rank r being PE r - 1) until every job's result has been accepted, and
// returns the farm's record. accept(job, server, result) gets each result that counts, once per
// job; tick(progress) runs every refreshSeconds and at the end. contentHash: a hash of what every
// server must hold alike (the scene); a server whose hash differs fails the run (InputError).
// lost(rank) is called as each server is declared lost. Throws FarmServerFailed when a server
// reports a failure, and std::runtime_error when every server is lost with jobs left (either
// way every server has been told to stop), FarmSharedPrepassLost as described there.
FarmRecord runFarmMaster(Transport& transport, const FarmOptions& options, std::uint64_t contentHash,
                         const TaskSet& jobs, Scheduler& order, const ScheduleParams& params,
                         const std::function<void(int job, int server, std::span<const std::byte> result)>& accept,
                         const std::function<void(const FarmProgress&)>& tick, const std::function<void(int rank)>& lost);

// On every other rank: says hello with contentHash and its PEs, runs prepare() (its pre-passes),
// then does the jobs it is sent, work(job) making each one's result, until the master says stop;
// during prepare and work it tells the master every quarter deadline that it is alive. A server that says
// hello and then falls silent for deadlineSeconds before it is ready is lost like one holding jobs.
// A failure of prepare or work is reported to the master and rethrown; a master that stops
// answering for deadlineSeconds (readySeconds for the welcome) ends every rank
// (Transport::abortAll, status 1); when the master stops the farm because of another rank's
// failure, throws FailedElsewhere (runtime.h).
void runFarmServer(Transport& transport, const FarmOptions& options, std::uint64_t contentHash, int pes,
                   const std::function<PrepareTraffic()>& prepare, const std::function<Bytes(int job)>& work);

// A fault for tests (PARRENDER_FARM_FAULT="RANK:JOBS:SIGNAL[:PIDFILE]"): the server on rank RANK,
// having sent JOBS results, as it starts its next job (so it holds at least that one), writes
// its process id to PIDFILE (when given) and raises SIGNAL (a number: 9 kills it, 19 stops it
// until a SIGCONT, after which it finishes the job and sends a late result); JOBS -1: as it
// starts its pre-passes. RANK 0: the master, once it has accepted JOBS results. Read by
// runFarmServer and runFarmMaster.
struct FarmFault {
  int rank = -1, afterJobs = 0, signal = 0;
  std::string pidFile;
};
// Throws pr::InputError for a malformed value; rank -1 when the variable is unset.
FarmFault farmFaultFromEnvironment();

}  // namespace pr::par
