// Simulator: the scheduling strategies of schedulers/ driven in virtual time, for any P from 1
// to 1024, from per-task costs (a recorded run's timeline or a cost table) and a communication
// model (latency per message + bytes / bandwidth). It answers "what would this scene do on 30
// machines, or 300?" from a laptop. The same Scheduler objects as the thread engine make the
// decisions; the result is a RunRecord, so metrics.cpp derives every figure the same way.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/run_record.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/task.h"

namespace pr::par {

struct NetworkModel {
  std::string_view name;
  double latencySeconds = 0.0;  // per message
  double bytesPerSecond = 0.0;  // 0: infinite bandwidth
  std::string_view description;

  double seconds(std::uint64_t messages, std::uint64_t bytes) const {
    return messages * latencySeconds + (bytesPerSecond > 0.0 ? bytes / bytesPerSecond : 0.0);
  }
};
// Presets: zero, shared-memory, 10gbe, 1gbe, 100mbit (a 1990s workstation farm).
const std::vector<NetworkModel>& networks();
// Throws pr::InputError naming the unknown network and listing the presets.
const NetworkModel& networkByName(std::string_view name);
std::string describeNetworks();

// One stage's work. tasks is what the scheduler sees (estimates, positions); costs are the
// seconds each task really takes; messages/bytes the data messages each task sends (empty:
// none). A sender pays latency + bytes/bandwidth for its messages inside the task.
struct SimStage {
  std::string name;
  TaskSet tasks;
  std::vector<double> costs;
  std::vector<std::uint32_t> messages;
  std::vector<std::uint64_t> bytes;
};
struct Workload {
  std::vector<SimStage> stages;
  std::string schedule;  // recorded schedule, empty for a cost table
  int grain = 1;
  int recordedPes = 0;   // 0 for a cost table
  double recordedWallSeconds = 0.0;
  // Time the record spent in message handlers: message-driven phases are not replayed (their
  // dependencies are not in the record), so this much busy time is outside the prediction.
  double unmodelledSeconds = 0.0;
};

// Each task's cost is its measured span; estimates and positions are the recorded TaskSet's.
// Throws pr::InputError when a stage has tasks but the record has no timeline for them.
Workload workloadFromRecord(const RunRecord& record, const std::string& origin);
// A cost table: one task per line, "cost" or "cost x y" (seconds, position); '#' starts a
// comment. One stage named "costs"; the estimate of each task is its cost.
Workload workloadFromCostTable(const std::string& text, const std::string& origin);
// A JSON run record (written with --metrics) or a cost table, told apart by the first character.
Workload readWorkload(const std::filesystem::path& file);

struct SimOptions {
  int pes = 1;
  ScheduleParams params;
  NetworkModel network;   // zero cost by default
  bool recordTimeline = false;
};

// Runs every stage of the workload under `schedule` in virtual time. PEs ask for work in order
// of virtual time, ties by lower PE id; a PE waiting for a task packet is idle for the request
// and packet latencies plus the packet's bytes over the bandwidth (refills ahead of need are
// counted as traffic but not waited for). wallSeconds of the result is the makespan.
RunRecord simulate(const Workload& workload, Scheduler& scheduler, const SimOptions& options);
RunRecord simulate(const Workload& workload, std::string_view schedule, const SimOptions& options);

}  // namespace pr::par
