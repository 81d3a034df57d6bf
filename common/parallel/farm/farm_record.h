// What a farm run (farm.h) leaves in its run record: every server, the jobs it did, its busy
// and idle time, and for a server declared lost when that was and which jobs were handed on;
// every job, who did it and when. Times are seconds on the master's clock since the farm began.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pr::par {

struct FarmServerRecord {
  int rank = 0;
  int pes = 1;                  // the server's own PEs (--threads)
  double prepareSeconds = 0.0;  // its pre-passes (BVH, photon maps, irradiance cache), as it measured them
  // Shared pre-passes: the messages and bytes between servers its run record booked.
  std::uint64_t prepareMessages = 0, prepareBytes = 0;
  double busySeconds = 0.0;     // doing jobs whose results counted
  double idleSeconds = 0.0;     // waiting for a job after its pre-passes, as it last reported
  std::vector<int> jobs;        // the jobs whose results counted, in the order they arrived
  double lostAtSeconds = -1.0;  // when the master declared it lost; < 0: it was not
  double lastHeardSeconds = 0.0;  // its last message before that
  std::vector<int> handedOn;    // the jobs it held when lost, handed to the others
  int lateResults = 0;          // results it sent for jobs it no longer held (discarded)
  double cpuSeconds = 0.0;      // its process's CPU time from hello to goodbye (0: it said no goodbye)
  bool lost() const { return lostAtSeconds >= 0.0; }
};

struct FarmJobRecord {
  int job = 0;
  int server = -1;           // the rank whose result counted
  double sentSeconds = 0.0;  // when the master sent it to that server
  double doneSeconds = 0.0;  // when its result arrived
  double busySeconds = 0.0;  // the server's time on it
  int attempts = 1;          // servers it was sent to (more than one: handed on)
  std::size_t resultBytes = 0;
};

struct FarmRecord {
  std::string schedule;  // the master's order of jobs
  std::string prepass = "replicated";  // every server runs the pre-passes whole, or "shared" among them
  double deadlineSeconds = 0.0;
  int jobsAhead = 1;
  std::string jobShape;  // what a job is, e.g. "screen area 32x24"
  double wallSeconds = 0.0;
  std::vector<FarmServerRecord> servers;  // one per server rank, in rank order
  std::vector<FarmJobRecord> jobs;        // one per job, in job order
};

}  // namespace pr::par
