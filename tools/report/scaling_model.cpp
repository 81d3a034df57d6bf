// Predicted and fitted speed-up (see scaling_model.h).
#include "tools/report/scaling_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/parallel/metrics.h"

namespace pr::cli::report {

std::vector<PredictedPoint> predictScaling(const par::RunRecord& record, const par::NetworkModel& network,
                                           const std::vector<int>& pes, double measuredOneSeconds) {
  const par::Workload workload = par::workloadFromRecord(record, "the report's run");
  std::vector<PredictedPoint> out;
  double one = 0.0;
  for (int p : pes) {
    par::SimOptions options;
    options.pes = p;
    options.params.grain = workload.grain;
    options.network = network;
    const par::Prediction prediction = par::predict(workload, "", options);
    const par::RunSummary summary = par::summarize(prediction.record);
    PredictedPoint point;
    point.pes = p;
    point.seconds = prediction.record.wallSeconds;
    point.imbalance = summary.total.imbalance;
    point.notes = prediction.stages;
    if (p == 1) one = measuredOneSeconds > 0.0 ? measuredOneSeconds : point.seconds;
    out.push_back(point);
  }
  for (PredictedPoint& point : out) {
    point.speedup = point.seconds > 0.0 && one > 0.0 ? one / point.seconds : 0.0;
    point.efficiency = point.speedup / point.pes;
  }
  return out;
}

double fittedSerialFraction(const std::vector<std::pair<int, double>>& speedups) {
  double sum = 0.0;
  int n = 0;
  for (const auto& [p, s] : speedups) {
    if (p <= 1 || !(s > 0.0)) continue;
    sum += (1.0 / s - 1.0 / p) / (1.0 - 1.0 / p);
    ++n;
  }
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : std::clamp(sum / n, 0.0, 1.0);
}

double amdahlSpeedup(double f, int pes) { return 1.0 / (f + (1.0 - f) / pes); }

std::vector<int> powersOfTwo(int most) {
  std::vector<int> out;
  for (int p = 1; p <= most; p *= 2) out.push_back(p);
  return out;
}

}  // namespace pr::cli::report
