// Metrics: the only code that turns RunRecords (measured or simulated) into figures — min/mean/
// max over PEs of every per-PE figure, load imbalance, serial fraction, utilisation, time at
// synchronisation points, computation-to-communication ratio — and runs at several P into
// speed-up, efficiency and the Karp-Flatt serial fraction. Reports, JSON, the CLI and tests all read these.
#pragma once

#include <string>
#include <vector>

#include "common/parallel/run_record.h"

namespace pr::par {

struct Spread {
  double min = 0.0, mean = 0.0, max = 0.0;
};
Spread spreadOf(const std::vector<double>& values);

// max(busy) / mean(busy) - 1 over one stage's PEs (shared/DESIGN.md); 0 for no work at all.
double loadImbalance(const std::vector<double>& busySeconds);

// The per-PE figures, by their JSON/C++ name, in a fixed order, each with where it comes from:
// "measured" (a clock or a counter at the event) or "modelled: ..." (how it is derived).
struct PeFigure {
  const char* name;
  double (*get)(const PeStageRecord&);
  const char* provenance;
};
const std::vector<PeFigure>& peFigures();

// Messages and bytes between PEs of one kind: a MessageKind of the channels ("primitives",
// "pixels", "rays", "results", "requests", "data"), "tasks" (scheduling traffic, modelled
// sizes) or "broadcasts" (replicated data, once per receiving PE). Of those, the messages and
// bytes that crossed between ranks (processes): a channel's messages to a PE on another rank,
// the task requests and answers of PEs on another rank than the controller's (rank 0), and the
// copy of each broadcast that reaches every other rank's first PE (a broadcast's root is on
// rank 0); the rest stayed within a rank. All within a rank on one process.
struct KindTraffic {
  std::string kind;
  std::uint64_t messages = 0, bytes = 0;
  std::uint64_t betweenRankMessages = 0, betweenRankBytes = 0;
};

struct StageSummary {
  std::string name;      // "total" for the whole run
  std::string schedule;
  double wallSeconds = 0.0;
  std::vector<Spread> figures;  // one per peFigures() entry
  // A stage's load imbalance: max(busy) / mean(busy) - 1 over its PEs, 0 for a stage run on one
  // PE by design (serial). The whole run's: the parallel stages' imbalances weighted by their
  // wall time (shared/DESIGN.md), so that a serial stage is no imbalance and opposite
  // imbalances in two stages do not cancel.
  double imbalance = 0.0;
  bool serial = false;  // a stage run on one PE by design (StageRecord::kind "one PE")
  // The whole run only: the share of its wall time in serial stages and in the controlling
  // thread between stages (Amdahl's serial term, as measured); 0 on a stage.
  double serialFraction = 0.0;
  double utilisation = 0.0;      // sum(busy) / (P * wall): the share of the PEs' time spent working
  double syncWaitSeconds = 0.0;  // summed over PEs
  // sum(busy - comm) / sum(comm), the seed's computation-to-communication ratio; < 0 when no
  // time was spent communicating (no messages).
  double computeToComm = -1.0;
  std::uint64_t tasks = 0, messages = 0, bytes = 0, schedulingMessages = 0, schedulingBytes = 0;
  std::vector<KindTraffic> byKind;  // channel kinds in first-seen order, then tasks and broadcasts

  const Spread& figure(const std::string& name) const;
};

// A named algorithm counter of the run record, over PEs.
struct CounterSummary {
  std::string name;
  Spread spread;
  double total = 0.0;
};

struct RunSummary {
  int pes = 1;
  int ranks = 1;
  double wallSeconds = 0.0;
  std::vector<StageSummary> stages;
  std::vector<CounterSummary> counters;
  StageSummary total;  // per-PE figures summed over stages first
};

// Per-PE totals over all stages.
std::vector<PeStageRecord> peTotals(const RunRecord& record);
RunSummary summarize(const RunRecord& record);
// Traffic of one stage by kind (see KindTraffic), its PEs spread over `ranks` ranks.
std::vector<KindTraffic> trafficByKind(const StageRecord& stage, int ranks = 1);
// A readable table: one row per stage and a total row; figures as min/mean/max.
std::string formatSummary(const RunSummary& summary);

// ---- runs at several P ----
struct ScalingPoint {
  int pes = 1;
  double seconds = 0.0;  // wall time (measured) or makespan (simulated)
};
struct ScalingRow {
  int pes = 1;
  double seconds = 0.0;
  double speedup = 0.0;        // T1 / Tn
  double speedupSerial = 0.0;  // Ts / Tn, 0 when Ts is not known
  double efficiency = 0.0;     // speedup / P
  double karpFlatt = 0.0;      // (1/S - 1/P) / (1 - 1/P), the serial fraction Amdahl's law implies; NaN at P = 1
};
// Beyond saturationPes adding PEs buys less than this fraction of the best time.
inline constexpr double kSaturationTolerance = 0.05;
struct ScalingTable {
  std::vector<ScalingRow> rows;  // by increasing P
  int bestPes = 1;               // the P with the lowest time
  int saturationPes = 1;         // the smallest P within kSaturationTolerance of the best time
};
// Needs a point at P = 1 (T1); throws pr::InputError otherwise. serialSeconds = Ts, or 0.
ScalingTable scalingTable(std::vector<ScalingPoint> points, double serialSeconds = 0.0);
std::string formatScaling(const ScalingTable& table);

}  // namespace pr::par
