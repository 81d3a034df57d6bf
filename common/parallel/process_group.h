// ProcessGroup: the ranks of this run - one when parrender runs on its own, R when mpirun
// launched R copies of it - and the bounded protocol by which they start and end together.
// Under mpirun (OMPI_COMM_WORLD_SIZE set) the MPI transport module is opened and MPI
// initialised; otherwise the group has one rank and MPI is never touched. Every wait for
// another rank is bounded by timeoutSeconds(): a rank that does not answer in time ends every
// rank, so a failure can never hang the run.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/transport.h"

namespace pr::par {

class ProcessGroup {
 public:
  // Tags of the group's own messages; others use tags from kFirstUserTag on.
  static constexpr int kCommandLineTag = 101, kVerdictTag = 102, kStatusTag = 103, kFinishTag = 104,
                       kAloneTag = 105;
  static constexpr int kFirstUserTag = 1000;

  // Creates this process's group (once, first thing in main). Under mpirun, throws
  // pr::InputError for a bad PARRENDER_RANK_TIMEOUT and std::runtime_error when MPI cannot be
  // started.
  static ProcessGroup& start(int* argc, char*** argv);
  static ProcessGroup& get();  // the group start() made

  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  Transport& transport();  // ranks() > 1 only
  // How long any wait for another rank may last: $PARRENDER_RANK_TIMEOUT seconds, default 300.
  double timeoutSeconds() const { return timeout_; }

  // A message with `tag` (from any rank), waiting at most timeoutSeconds(); past that, ends
  // every rank with a message naming `what` (abortAll), since a rank that stopped answering
  // cannot take part in a clean ending.
  Envelope receive(int tag, std::string_view what);

  // Whether every rank was started with this command line: each rank's hash goes to rank 0,
  // which compares it with its own and answers. Throws pr::InputError on every rank when one
  // differs (rank 0's message names the first such rank; the others' is empty).
  void checkSameCommandLine(int argc, char** argv);

  // Runs `work` on rank 0 alone while every other rank waits, and returns its result on every
  // rank (sent from rank 0 to each: a one-PE baseline that commands running across ranks
  // measure, or a fact only rank 0 can learn, such as whether a file is cached). The wait stays
  // bounded however long the work takes: rank 0 tells the others it is still working every
  // few seconds, and a rank that hears nothing for timeoutSeconds() ends every rank. A failure
  // of `work` is rethrown on rank 0 and becomes FailedElsewhere on the others. One rank: work().
  Bytes onRank0Alone(std::string_view what, const std::function<Bytes()>& work);

  // Ends the run on this rank with `status` (0, or a failure's exit status with its message)
  // and returns the status the process exits with: the same on every rank. Rank 0 collects
  // every rank's status (bounded), prints one failure as soon as it knows it - its own, else
  // the first to arrive with a message - naming the rank, and tells every rank the run's
  // status; then every rank leaves MPI. A failure another rank reports (FailedElsewhere) is
  // passed with an empty message.
  int finish(int status, const std::string& error);

  // On rank 0: rank `rank` was lost during the run (a farm server that died or stopped
  // answering, farm/farm.h). finish() then does not wait for its status, and since MPI_Finalize
  // would wait for ever for a rank that still exists but does not answer, the run ends without
  // it: the other ranks leave without MPI_Finalize once they have the verdict (a lost rank that
  // woke up too), and rank 0 ends the job with abortAll(the run's status); under
  // `mpirun --enable-recovery`, Open MPI 4.1's mpirun exits 0 whatever that status is.
  void markLost(int rank);

  // On rank 0: called by finish() (or abortRun) with the run's exit status once it is known,
  // before the run ends (a farm's --farm-status file: under `mpirun --enable-recovery`, Open
  // MPI 4.1's mpirun exits 0 whatever the ranks' status, so it has to reach the user another way).
  void atVerdict(std::function<void(int status)> hook) { atVerdict_ = std::move(hook); }

  // Ends every rank now with `status`, printing `error` as this rank's failure and running the
  // verdict hook first: for a rank that knows the others cannot take part in an ending (they
  // wait for a rank that is gone).
  [[noreturn]] void abortRun(int status, const std::string& error);

 private:
  ProcessGroup() = default;
  int rank_ = 0, ranks_ = 1;
  double timeout_ = 300.0;
  Transport* transport_ = nullptr;
  std::vector<bool> lost_;  // rank 0: ranks markLost named
  std::function<void(int)> atVerdict_;
};

// The ranks mpirun started and this process's rank among them, from the environment (before
// MPI is initialised); 1 and 0 without mpirun. Open MPI's mpirun only (OMPI_COMM_WORLD_*).
int launchedRanks();
int launchedRank();

// One failure line on stderr: "parrender: error: ..." (status 2) or "parrender: failed: ...",
// naming the rank when there are several.
void printFailure(int status, int rank, int ranks, const std::string& text);

}  // namespace pr::par
