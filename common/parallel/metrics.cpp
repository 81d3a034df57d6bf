// Derived figures (shared/STYLE.md §4: measured in one place, derived here only). Inputs are
// RunRecords from runtime.cpp or simulator.cpp; outputs feed JSON, tables and reports.
#include "common/parallel/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include "common/util/error.h"

namespace pr::par {

Spread spreadOf(const std::vector<double>& values) {
  if (values.empty()) return {};
  Spread s{values[0], 0.0, values[0]};
  for (double v : values) s.min = std::min(s.min, v), s.max = std::max(s.max, v), s.mean += v;
  s.mean /= static_cast<double>(values.size());
  return s;
}

double loadImbalance(const std::vector<double>& busy) {
  const Spread s = spreadOf(busy);
  return s.mean > 0.0 ? s.max / s.mean - 1.0 : 0.0;
}

const std::vector<PeFigure>& peFigures() {
  static constexpr const char* kMeasured = "measured";
  static const std::vector<PeFigure> kFigures = {
      {"busySeconds", [](const PeStageRecord& r) { return r.busySeconds; }, kMeasured},
      {"idleSeconds", [](const PeStageRecord& r) { return r.idleSeconds; }, kMeasured},
      {"syncWaitSeconds", [](const PeStageRecord& r) { return r.syncWaitSeconds; }, kMeasured},
      {"sendReceiveSeconds", [](const PeStageRecord& r) { return r.sendReceiveSeconds; }, kMeasured},
      {"messageWaitSeconds", [](const PeStageRecord& r) { return r.messageWaitSeconds; }, kMeasured},
      {"commSeconds", [](const PeStageRecord& r) { return r.commSeconds(); }, kMeasured},
      {"tasks", [](const PeStageRecord& r) { return double(r.tasks); }, kMeasured},
      {"messagesHandled", [](const PeStageRecord& r) { return double(r.messagesHandled); }, kMeasured},
      {"messagesSent", [](const PeStageRecord& r) { return double(r.messagesSent); }, kMeasured},
      {"bytesSent", [](const PeStageRecord& r) { return double(r.bytesSent); }, kMeasured},
      {"messagesReceived", [](const PeStageRecord& r) { return double(r.messagesReceived); }, kMeasured},
      {"bytesReceived", [](const PeStageRecord& r) { return double(r.bytesReceived); }, kMeasured},
      // Task hand-outs go through the shared scheduler, not a Channel: their count is measured,
      // their size is what a distributed implementation would send (scheduler.h).
      {"schedulingMessages", [](const PeStageRecord& r) { return double(r.schedulingMessages); },
       "modelled: one request and one task packet per hand-out from another PE or the controller, and per steal request answered empty"},
      {"schedulingBytes", [](const PeStageRecord& r) { return double(r.schedulingBytes); },
       "modelled: 16-byte requests, 16-byte packet headers and 8 bytes per task id"},
      {"broadcastBytesReceived", [](const PeStageRecord& r) { return double(r.broadcastBytesReceived); },
       "measured: bytes of the replicated data each PE receives (every PE but the one that holds it)"},
      {"replicatedBytes", [](const PeStageRecord& r) { return double(r.replicatedBytes); },
       "measured: bytes of the replicated data another rank's first PE made itself (loaded, built) instead of receiving"},
      {"cacheHits", [](const PeStageRecord& r) { return double(r.cacheHits); }, kMeasured},
      {"cacheMisses", [](const PeStageRecord& r) { return double(r.cacheMisses); }, kMeasured},
      {"prefetches", [](const PeStageRecord& r) { return double(r.prefetches); }, kMeasured},
  };
  return kFigures;
}

const Spread& StageSummary::figure(const std::string& figureName) const {
  const auto& all = peFigures();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (figureName == all[i].name) return figures.at(i);
  PR_CHECK(false, "unknown per-PE figure " + figureName);
  return figures.front();
}

namespace {

StageSummary summarizePes(const std::string& name, const std::string& schedule, double wall,
                          const std::vector<PeStageRecord>& pes) {
  StageSummary s;
  s.name = name;
  s.schedule = schedule;
  s.wallSeconds = wall;
  std::vector<double> values(pes.size()), busy(pes.size());
  for (const PeFigure& f : peFigures()) {
    for (std::size_t p = 0; p < pes.size(); ++p) values[p] = f.get(pes[p]);
    s.figures.push_back(spreadOf(values));
  }
  double busySum = 0.0, sendReceiveSum = 0.0, commSum = 0.0;
  for (std::size_t p = 0; p < pes.size(); ++p) {
    const PeStageRecord& r = pes[p];
    busy[p] = r.busySeconds;
    busySum += r.busySeconds;
    sendReceiveSum += r.sendReceiveSeconds;
    commSum += r.commSeconds();
    s.syncWaitSeconds += r.syncWaitSeconds;
    s.tasks += r.tasks;
    s.messages += r.messagesSent;
    s.bytes += r.bytesSent;
    s.schedulingMessages += r.schedulingMessages;
    s.schedulingBytes += r.schedulingBytes;
  }
  s.imbalance = loadImbalance(busy);
  s.utilisation = wall > 0.0 && !pes.empty() ? busySum / (wall * pes.size()) : 0.0;
  // Computation is busy time outside Channel calls; communication is those calls plus waiting
  // for messages (seed 3.1.3's ratio, from measured times only).
  s.computeToComm = commSum > 0.0 ? std::max(0.0, busySum - sendReceiveSum) / commSum : -1.0;
  return s;
}

}  // namespace

std::vector<PeStageRecord> peTotals(const RunRecord& record) {
  std::vector<PeStageRecord> totals(record.pes);
  for (const StageRecord& stage : record.stages) {
    for (std::size_t p = 0; p < stage.pes.size() && p < totals.size(); ++p) {
      const PeStageRecord& r = stage.pes[p];
      PeStageRecord& t = totals[p];
      t.busySeconds += r.busySeconds;
      t.idleSeconds += r.idleSeconds;
      t.syncWaitSeconds += r.syncWaitSeconds;
      t.sendReceiveSeconds += r.sendReceiveSeconds;
      t.messageWaitSeconds += r.messageWaitSeconds;
      t.tasks += r.tasks;
      t.messagesHandled += r.messagesHandled;
      t.messagesSent += r.messagesSent;
      t.bytesSent += r.bytesSent;
      t.messagesReceived += r.messagesReceived;
      t.bytesReceived += r.bytesReceived;
      t.schedulingMessages += r.schedulingMessages;
      t.schedulingBytes += r.schedulingBytes;
      t.broadcastsReceived += r.broadcastsReceived;
      t.broadcastBytesReceived += r.broadcastBytesReceived;
      t.replicatedCopies += r.replicatedCopies;
      t.replicatedBytes += r.replicatedBytes;
      t.cacheHits += r.cacheHits;
      t.cacheMisses += r.cacheMisses;
      t.prefetches += r.prefetches;
    }
  }
  return totals;
}

namespace {

void addTraffic(std::vector<KindTraffic>& into, const KindTraffic& add) {
  if (add.messages == 0 && add.bytes == 0) return;
  auto it = std::find_if(into.begin(), into.end(), [&](const KindTraffic& k) { return k.kind == add.kind; });
  if (it == into.end()) it = into.insert(into.end(), KindTraffic{add.kind});
  it->messages += add.messages;
  it->bytes += add.bytes;
  it->betweenRankMessages += add.betweenRankMessages;
  it->betweenRankBytes += add.betweenRankBytes;
}

}  // namespace

std::vector<KindTraffic> trafficByKind(const StageRecord& stage, int ranks) {
  std::vector<KindTraffic> kinds;
  for (const ChannelTraffic& c : stage.channels)
    addTraffic(kinds, {c.kind, c.messages, c.bytes, c.betweenRankMessages, c.betweenRankBytes});
  KindTraffic tasks{"tasks"}, broadcasts{"broadcasts"};
  const std::size_t perRank = std::max<std::size_t>(1, stage.pes.size() / std::size_t(std::max(1, ranks)));
  for (std::size_t p = 0; p < stage.pes.size(); ++p) {
    const PeStageRecord& r = stage.pes[p];
    tasks.messages += r.schedulingMessages;
    tasks.bytes += r.schedulingBytes;
    tasks.betweenRankMessages += r.schedulingMessagesBetweenRanks;
    tasks.betweenRankBytes += r.schedulingBytesBetweenRanks;
    broadcasts.messages += r.broadcastsReceived;
    broadcasts.bytes += r.broadcastBytesReceived;
    if (p % perRank == 0 && p >= perRank) {  // another rank's first PE: its copy came from rank 0
      broadcasts.betweenRankMessages += r.broadcastsReceived;
      broadcasts.betweenRankBytes += r.broadcastBytesReceived;
    }
  }
  addTraffic(kinds, tasks);
  addTraffic(kinds, broadcasts);
  return kinds;
}

RunSummary summarize(const RunRecord& record) {
  RunSummary summary;
  summary.pes = record.pes;
  summary.ranks = record.ranks;
  summary.wallSeconds = record.wallSeconds;
  double stageWall = 0.0, serialWall = 0.0, parallelWall = 0.0, weightedImbalance = 0.0;
  std::vector<KindTraffic> byKind;
  for (const StageRecord& stage : record.stages) {
    StageSummary& s = summary.stages.emplace_back(summarizePes(stage.name, stage.schedule, stage.wallSeconds, stage.pes));
    s.byKind = trafficByKind(stage, record.ranks);
    for (const KindTraffic& k : s.byKind) addTraffic(byKind, k);
    stageWall += stage.wallSeconds;
    s.serial = stage.kind == kOnePeStage;
    if (s.serial) {
      s.imbalance = 0.0;  // by design, not by imbalance: the serial fraction below
      serialWall += stage.wallSeconds;
    } else {
      parallelWall += stage.wallSeconds;
      weightedImbalance += stage.wallSeconds * s.imbalance;
    }
  }
  // Utilisation of the whole run over the time spent in stages; the controller's serial code
  // between stages is not PE time.
  summary.total = summarizePes("total", record.schedule, stageWall, peTotals(record));
  summary.total.imbalance = parallelWall > 0.0 ? weightedImbalance / parallelWall : 0.0;
  const double between = std::max(0.0, record.wallSeconds - stageWall);
  summary.total.serialFraction = record.wallSeconds > 0.0 ? std::min(1.0, (serialWall + between) / record.wallSeconds) : 0.0;
  // Channel kinds first, then the runtime's own kinds, whatever order the stages saw them in.
  std::stable_partition(byKind.begin(), byKind.end(),
                        [](const KindTraffic& k) { return k.kind != "tasks" && k.kind != "broadcasts"; });
  summary.total.byKind = std::move(byKind);
  for (const CounterRecord& c : record.counters) {
    double total = 0.0;
    for (double v : c.perPe) total += v;
    summary.counters.push_back({c.name, spreadOf(c.perPe), total});
  }
  return summary;
}

namespace {

std::string number(double v) {
  char buffer[32];
  const double a = std::abs(v);
  if (a != 0.0 && (a < 1e-3 || a >= 1e7))
    std::snprintf(buffer, sizeof buffer, "%.3g", v);
  else if (v == std::floor(v) && a < 1e7)
    std::snprintf(buffer, sizeof buffer, "%.0f", v);
  else
    std::snprintf(buffer, sizeof buffer, "%.4f", v);
  return buffer;
}

}  // namespace

std::string formatSummary(const RunSummary& summary) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "P = %d, wall %.6f s\n", summary.pes, summary.wallSeconds);
  out += line;
  std::snprintf(line, sizeof line, "%-14s %-14s %10s %9s %8s %11s %9s %10s %12s\n", "stage", "schedule", "wall s",
                "imbalance", "utilis.", "sync wait s", "tasks", "messages", "bytes");
  out += line;
  auto row = [&](const StageSummary& s) {
    char imbalance[16];
    std::snprintf(imbalance, sizeof imbalance, s.serial ? "serial" : "%.4f", s.imbalance);
    std::snprintf(line, sizeof line, "%-14s %-14s %10.6f %9s %8.4f %11.6f %9llu %10llu %12llu\n", s.name.c_str(),
                  s.schedule.c_str(), s.wallSeconds, imbalance, s.utilisation, s.syncWaitSeconds,
                  (unsigned long long)s.tasks, (unsigned long long)s.messages, (unsigned long long)s.bytes);
    out += line;
  };
  for (const StageSummary& s : summary.stages) row(s);
  row(summary.total);
  std::snprintf(line, sizeof line,
                "total imbalance: the parallel stages' imbalances weighted by their wall time; serial fraction %.4f (stages run on "
                "one PE by design and the time between stages)\n",
                summary.total.serialFraction);
  out += line;
  out += "per-PE figures over the run (min / mean / max):\n";
  const auto& figures = peFigures();
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const Spread& s = summary.total.figures[i];
    std::snprintf(line, sizeof line, "  %-24s %14s %14s %14s\n", figures[i].name, number(s.min).c_str(),
                  number(s.mean).c_str(), number(s.max).c_str());
    out += line;
  }
  for (const CounterSummary& c : summary.counters) {
    std::snprintf(line, sizeof line, "  %-24s %14s %14s %14s  (total %s)\n", c.name.c_str(), number(c.spread.min).c_str(),
                  number(c.spread.mean).c_str(), number(c.spread.max).c_str(), number(c.total).c_str());
    out += line;
  }
  if (!summary.total.byKind.empty()) {
    out += "traffic between PEs by kind:\n";
    for (const KindTraffic& k : summary.total.byKind) {
      std::snprintf(line, sizeof line, "  %-12s %12llu messages %16llu bytes", k.kind.c_str(),
                    (unsigned long long)k.messages, (unsigned long long)k.bytes);
      out += line;
      if (summary.ranks > 1) {
        std::snprintf(line, sizeof line, "  (between ranks %llu messages, %llu bytes)", (unsigned long long)k.betweenRankMessages,
                      (unsigned long long)k.betweenRankBytes);
        out += line;
      }
      out += "\n";
    }
  }
  if (summary.total.computeToComm >= 0.0) {
    std::snprintf(line, sizeof line, "computation-to-communication ratio: %.1f\n", summary.total.computeToComm);
    out += line;
  }
  return out;
}

ScalingTable scalingTable(std::vector<ScalingPoint> points, double serialSeconds) {
  std::sort(points.begin(), points.end(), [](const ScalingPoint& a, const ScalingPoint& b) { return a.pes < b.pes; });
  if (points.empty() || points.front().pes != 1)
    throw InputError("speed-up needs a run at P = 1 (T1)");
  const double t1 = points.front().seconds;
  ScalingTable table;
  double best = std::numeric_limits<double>::infinity();
  for (const ScalingPoint& pt : points) {
    ScalingRow row;
    row.pes = pt.pes;
    row.seconds = pt.seconds;
    row.speedup = pt.seconds > 0.0 ? t1 / pt.seconds : 0.0;
    row.speedupSerial = serialSeconds > 0.0 && pt.seconds > 0.0 ? serialSeconds / pt.seconds : 0.0;
    row.efficiency = row.speedup / pt.pes;
    // Karp & Flatt (1990): e = (1/S - 1/P) / (1 - 1/P), undefined at P = 1.
    row.karpFlatt = pt.pes > 1 && row.speedup > 0.0
                        ? (1.0 / row.speedup - 1.0 / pt.pes) / (1.0 - 1.0 / pt.pes)
                        : std::numeric_limits<double>::quiet_NaN();
    if (pt.seconds < best) best = pt.seconds, table.bestPes = pt.pes;
    table.rows.push_back(row);
  }
  for (const ScalingRow& row : table.rows) {
    if (row.seconds <= best * (1.0 + kSaturationTolerance)) {
      table.saturationPes = row.pes;
      break;
    }
  }
  return table;
}

std::string formatScaling(const ScalingTable& table) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%6s %14s %10s %10s %10s %11s\n", "P", "time s", "T1/Tn", "Ts/Tn", "effic.",
                "Karp-Flatt");
  out += line;
  for (const ScalingRow& r : table.rows) {
    const std::string ts = r.speedupSerial > 0.0 ? number(r.speedupSerial) : "-";
    const std::string kf = std::isnan(r.karpFlatt) ? "-" : number(r.karpFlatt);
    std::snprintf(line, sizeof line, "%6d %14.6f %10.3f %10s %10.4f %11s\n", r.pes, r.seconds, r.speedup, ts.c_str(),
                  r.efficiency, kf.c_str());
    out += line;
  }
  std::snprintf(line, sizeof line, "best P measured: %d; adding PEs beyond P = %d gains less than %.0f%%\n",
                table.bestPes, table.saturationPes, kSaturationTolerance * 100.0);
  out += line;
  return out;
}

}  // namespace pr::par
