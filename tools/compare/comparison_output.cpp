// The comparison's table, CSV and JSON (see comparison_output.h).
#include "tools/compare/comparison_output.h"

#include "common/parallel/farm/farm_record_json.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <vector>

namespace pr::cli {

std::string formatNumber(double v, const char* format) {
  char text[48];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

namespace {

std::string number(double v, const char* format = "%.3f") { return formatNumber(v, format); }

std::string exact(double v) { return number(v, "%.6g"); }

// 1234567 -> "1.2M": the table's compact counts.
std::string compact(std::uint64_t v) {
  if (v < 10000) return std::to_string(v);
  const char* units = "KMGT";
  double x = double(v);
  int unit = -1;
  while (x >= 1000.0 && unit < 3) x /= 1000.0, ++unit;
  return number(x, x < 10.0 ? "%.1f" : "%.0f") + units[unit];
}

// A CSV field in double quotes, its own quotes doubled.
std::string csvText(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string orDash(double v, bool known, const char* format = "%.2f") { return known ? number(v, format) : "-"; }

// Left-aligned text columns then right-aligned figures, each as wide as its widest cell.
std::string layout(const std::vector<std::vector<std::string>>& cells, std::size_t textColumns) {
  std::vector<std::size_t> width;
  for (const auto& line : cells)
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (width.size() <= i) width.push_back(0);
      width[i] = std::max(width[i], line[i].size());
    }
  std::string out;
  for (const auto& line : cells) {
    std::string text;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const std::string pad(width[i] - line[i].size(), ' ');
      text += (i ? "  " : "") + (i < textColumns ? line[i] + pad : pad + line[i]);
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    out += text + "\n";
  }
  return out;
}

// P, and where its PEs ran: "4 (2x2)" on 2 ranks, "4 (2x2+master)" for a farm of 2 servers.
std::string placementText(const Combination& c) {
  if (!c.farm.empty())
    return std::to_string(c.pes) + " (" + std::to_string(c.ranks - 1) + "x" + std::to_string(c.pesPerProcess()) + "+master)";
  if (c.ranks > 1) return std::to_string(c.pes) + " (" + std::to_string(c.ranks) + "x" + std::to_string(c.pesPerProcess()) + ")";
  return std::to_string(c.pes);
}

}  // namespace

std::string comparisonTable(const Comparison& c) {
  std::vector<std::string> kinds;
  for (const std::string& k : comparisonKinds())
    for (const ComparisonRow& row : c.rows)
      if (const par::KindTraffic* t = kindTraffic(row, k); t && t->messages > 0) {
        kinds.push_back(k);
        break;
      }
  std::vector<std::vector<std::string>> cells;
  std::vector<std::string> header = {"method", "family", "schedule", "integrator", "compositor", "P", "wall_s", "spread",
                                     "cpu_s", "T1/Tn", "Ts/Tn", "eff", "imbal", "serial", "messages", "bytes"};
  for (const std::string& k : kinds) header.push_back(k + " msg/B");
  // Under mpirun: what of every row's traffic crossed between ranks.
  const bool acrossRanks = std::any_of(c.rows.begin(), c.rows.end(), [](const ComparisonRow& r) { return r.what.ranks > 1; });
  if (acrossRanks) header.push_back("x-rank msg/B");
  for (const char* h : {"comp/comm", "hit", "rmse", "image"}) header.push_back(h);
  cells.push_back(header);
  for (const ComparisonRow& r : c.rows) {
    const par::StageSummary& t = r.summary.total;
    const par::KindTraffic all = allTraffic(r);
    std::vector<std::string> line = {r.what.methodName(),
                                     std::string(toString(r.what.family)),
                                     r.what.schedule,
                                     r.what.integrator,
                                     r.what.compositor,
                                     placementText(r.what),
                                     number(r.wall, "%.4g"),
                                     r.wall > 0.0 ? "±" + number(50.0 * (r.wallMax - r.wallMin) / r.wall, "%.0f") + "%" : "-",
                                     number(r.cpu, "%.4g"),
                                     orDash(r.speedup, r.speedup > 0.0),
                                     orDash(r.speedupSerial, r.speedupSerial > 0.0),
                                     orDash(r.efficiency, r.efficiency > 0.0),
                                     number(t.imbalance),
                                     number(t.serialFraction),
                                     compact(all.messages),
                                     compact(all.bytes)};
    for (const std::string& k : kinds) {
      const par::KindTraffic* kt = kindTraffic(r, k);
      line.push_back(kt ? compact(kt->messages) + "/" + compact(kt->bytes) : "-");
    }
    if (acrossRanks)
      line.push_back(r.what.ranks > 1 ? compact(all.betweenRankMessages) + "/" + compact(all.betweenRankBytes) : "-");
    line.push_back(orDash(t.computeToComm, t.computeToComm >= 0.0, "%.1f"));
    line.push_back(orDash(r.cacheHitRatio, r.cacheHitRatio >= 0.0, "%.3f"));
    line.push_back(orDash(r.rmse, r.rmse >= 0.0, "%.5f"));
    line.push_back(r.agrees ? (r.agreement == "reference" ? "ref" : "same") : "DIFFERS");
    cells.push_back(line);
  }
  return layout(cells, 5);
}

std::string comparisonNotes(const Comparison& c) {
  std::string out;
  for (const SkippedCombination& s : c.skipped) out += "skipped " + s.what + ": " + s.reason + "\n";
  for (const ComparisonRow& r : c.rows)
    if (!r.agrees) out += "IMAGE MISMATCH " + r.what.label() + ": " + r.agreement + "\n";
  if (c.mismatches == 0 && !c.rows.empty())
    out += "images: every render is bit-identical to the first of its family and integrator\n";
  for (const ComparisonRow& r : c.rows)
    if (r.record.farm) out += "\n" + r.what.label() + " (the median run):\n" + farmSummary(r.record);
  return out;
}

std::string comparisonCsv(const Comparison& c) {
  std::ostringstream out;
  out << "method,family,schedule,integrator,compositor,pes,repeats,wall_seconds,wall_min,wall_max,cpu_seconds,speedup,"
         "speedup_serial,efficiency,load_imbalance,messages,bytes";
  for (const std::string& k : comparisonKinds()) out << "," << k << "_messages," << k << "_bytes";
  out << ",compute_to_comm,cache_hit_ratio,rays,rmse,image_agrees,agreement,ranks,between_ranks_messages,between_ranks_bytes,"
         "farm_schedule,serial_fraction\n";
  for (const ComparisonRow& r : c.rows) {
    const par::StageSummary& t = r.summary.total;
    out << r.what.method << "," << toString(r.what.family) << "," << r.what.schedule << "," << r.what.integrator << ","
        << r.what.compositor << "," << r.what.pes << "," << r.wallSeconds.size() << "," << exact(r.wall) << ","
        << exact(r.wallMin) << "," << exact(r.wallMax) << "," << exact(r.cpu) << "," << exact(r.speedup) << ","
        << exact(r.speedupSerial) << "," << exact(r.efficiency) << "," << exact(t.imbalance) << "," << allTraffic(r).messages
        << "," << allTraffic(r).bytes;
    for (const std::string& k : comparisonKinds()) {
      const par::KindTraffic* kt = kindTraffic(r, k);
      out << "," << (kt ? kt->messages : 0) << "," << (kt ? kt->bytes : 0);
    }
    out << "," << exact(t.computeToComm) << "," << exact(r.cacheHitRatio) << "," << r.rays << "," << exact(r.rmse) << ","
        << (r.agrees ? "true" : "false") << "," << csvText(r.agreement) << "," << r.what.ranks << ","
        << allTraffic(r).betweenRankMessages << "," << allTraffic(r).betweenRankBytes << "," << r.what.farm << "," << exact(t.serialFraction) << "\n";
  }
  return out.str();
}

nlohmann::json comparisonJson(const Comparison& c) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ComparisonRow& r : c.rows) {
    const par::StageSummary& t = r.summary.total;
    nlohmann::json byKind = nlohmann::json::object();
    for (const par::KindTraffic& k : t.byKind)
      byKind[k.kind] = {{"messages", k.messages}, {"bytes", k.bytes}, {"betweenRankMessages", k.betweenRankMessages},
                        {"betweenRankBytes", k.betweenRankBytes}};
    auto optional = [](double v, bool known) { return known ? nlohmann::json(v) : nlohmann::json(nullptr); };
    rows.push_back({{"method", r.what.method},
                    {"family", toString(r.what.family)},
                    {"schedule", r.what.schedule},
                    {"integrator", r.what.integrator},
                    {"compositor", r.what.compositor},
                    {"pes", r.what.pes},
                    {"ranks", r.what.ranks},
                    {"wallSeconds", r.wallSeconds},
                    {"cpuSeconds", r.cpuSeconds},
                    {"wallMedian", r.wall},
                    {"cpuMedian", r.cpu},
                    {"speedup", optional(r.speedup, r.speedup > 0.0)},
                    {"speedupSerial", optional(r.speedupSerial, r.speedupSerial > 0.0)},
                    {"serialReference", r.serialReference},
                    {"efficiency", optional(r.efficiency, r.efficiency > 0.0)},
                    {"utilisation", t.utilisation},
                    {"loadImbalance", t.imbalance},
                    {"serialFraction", t.serialFraction},
                    {"messages", allTraffic(r).messages},
                    {"bytes", allTraffic(r).bytes},
                    {"betweenRankMessages", allTraffic(r).betweenRankMessages},
                    {"betweenRankBytes", allTraffic(r).betweenRankBytes},
                    {"byKind", byKind},
                    {"computeToComm", optional(t.computeToComm, t.computeToComm >= 0.0)},
                    {"cacheHitRatio", optional(r.cacheHitRatio, r.cacheHitRatio >= 0.0)},
                    {"rays", r.rays},
                    {"rmse", optional(r.rmse, r.rmse >= 0.0)},
                    {"imageAgrees", r.agrees},
                    {"agreement", r.agreement}});
    // A farm's servers and jobs, as its run record holds them.
    if (r.record.farm) rows.back()["farm"] = par::farmJson(*r.record.farm);
  }
  nlohmann::json skipped = nlohmann::json::array();
  for (const SkippedCombination& s : c.skipped) skipped.push_back({{"what", s.what}, {"reason", s.reason}});
  return {{"rows", rows},
          {"skipped", skipped},
          {"mismatches", c.mismatches},
          {"reference", c.reference.image.empty()
                            ? nlohmann::json(nullptr)
                            : nlohmann::json{{"integrator", "path"}, {"cached", c.reference.cached},
                                             {"cpuSeconds", c.reference.cpuSeconds}}}};
}

}  // namespace pr::cli
