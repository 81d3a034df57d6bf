// The farm (farm.h) at another number of servers, in virtual time: what a farm run's record
// predicts for S servers on a network model (simulator.h). Each job costs what its server
// measured (busySeconds, on servers of the recorded PEs each), handed out by the same schedule
// object in the same way (jobsAhead per server, the next job sent when a result arrives); every
// server first runs the pre-passes (the recorded servers' mean: a replicated computation, the
// same at any S); results funnel into the master one after another over its one link (latency
// plus bytes over the bandwidth), and a job reaches its server a latency (plus its few bytes)
// after the result that freed its place. A lost server's jobs are replayed as if done once.
// Shared pre-passes (FarmRecord::prepass) are kept at their recorded time too, though each
// server's share would shrink with more servers: the prediction is then an upper bound.
#pragma once

#include <vector>

#include "common/parallel/farm/farm_record.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/simulator.h"
#include "common/parallel/task.h"

namespace pr::par {

struct FarmPrediction {
  int servers = 0;
  double prepareSeconds = 0.0;  // every server's pre-passes
  double jobsSeconds = 0.0;     // from the first job sent to the last result received
  double makespanSeconds = 0.0;  // prepare + jobs
  double masterLinkSeconds = 0.0;  // the master's link busy with results
  std::vector<double> serverBusySeconds;
};

// tasks: the jobs as the master's schedule saw them (the record's "farm jobs" stage);
// jobBytes: a job message's size. Throws pr::InputError for servers < 1 or a record whose
// jobs are not all done.
FarmPrediction predictFarm(const FarmRecord& farm, const TaskSet& tasks, std::size_t jobBytes, int servers,
                           const NetworkModel& network, Scheduler& order, const ScheduleParams& params);

}  // namespace pr::par
