// Speed-up against P for the report: the simulator's prediction of a recorded run out to 1024
// PEs on a chosen network (common/parallel/simulator.h), and Amdahl's law with the serial
// fraction fitted to the measured points by Karp and Flatt (common/parallel/metrics.h).
#pragma once

#include <string>
#include <vector>

#include "common/parallel/run_record.h"
#include "common/parallel/simulator.h"

namespace pr::cli::report {

struct PredictedPoint {
  int pes = 1;
  double seconds = 0.0;     // predicted makespan
  double speedup = 0.0;     // against the baseline predictScaling was given
  double efficiency = 0.0;
  double imbalance = 0.0;
  std::vector<par::StageNote> notes;  // how each stage was replayed at this P, the excluded ones with why
};

// The record replayed at every P of `pes` (which must hold 1), each stage under its own
// recorded schedule. Speed-ups are against `measuredOneSeconds` when it is given (> 0: the
// measured T1, the baseline of the measured points beside them), else against the prediction
// at P = 1.
std::vector<PredictedPoint> predictScaling(const par::RunRecord& record, const par::NetworkModel& network,
                                           const std::vector<int>& pes, double measuredOneSeconds = 0.0);

// The mean Karp-Flatt serial fraction over the measured points at P > 1 (speed-ups T1/Tn),
// clamped to [0, 1]; NaN without such a point.
double fittedSerialFraction(const std::vector<std::pair<int, double>>& speedups);
// Amdahl's law: 1 / (f + (1 - f) / P).
double amdahlSpeedup(double serialFraction, int pes);

// 1, 2, 4, ... up to `most`.
std::vector<int> powersOfTwo(int most);

}  // namespace pr::cli::report
