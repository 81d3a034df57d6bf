// One scene's section of the report (see scene_report.h).
#include "tools/report/scene_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "common/image/image_io.h"
#include "common/parallel/metrics.h"
#include "common/parallel/process_group.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/util/atomic_file.h"
#include "common/util/memory_limit.h"
#include "raster/composite/compositor.h"
#include "tools/compare/comparison.h"
#include "tools/compare/comparison_output.h"
#include "tools/report/cache_sweep.h"
#include "tools/report/classification.h"
#include "tools/report/farm_section.h"
#include "tools/report/html.h"
#include "tools/report/scaling_model.h"
#include "tools/sweep/image_error.h"
#include "tools/sweep/sweep.h"

namespace pr::cli::report {

namespace {

// Gantt charts beyond this many spans draw the first ones only (and say so).
constexpr std::size_t kMaxTimelineSpans = 20000;

std::string fmt(double v, const char* format = "%.3g") { return formatNumber(v, format); }

// Bytes (or messages) of one kind in a row, 0 when none.
std::uint64_t kindBytes(const ComparisonRow& r, const std::string& kind, bool messages = false) {
  const par::KindTraffic* k = kindTraffic(r, kind);
  return !k ? 0 : messages ? k->messages : k->bytes;
}

// The analytic compositing volume of sort-last over the full frame: b A (1 - 1/P) per PE, and
// each message's header h (its two rectangles): P (P - 1) messages by direct-send, P log2 P by
// binary-swap.
double analyticCompositeBytes(int width, int height, int pes, const std::string& compositor) {
  const double messages = compositor == "binary-swap" ? double(pes) * std::log2(double(pes)) : double(pes) * double(pes - 1);
  return double(raster::kPixelBytes) * double(width) * double(height) * double(pes - 1) +
         double(raster::kPixelHeaderBytes) * messages;
}

// What one copy of a run's broadcasts is, whatever P (the record's stages say it even at P = 1):
// messages, or bytes.
std::uint64_t broadcastCopy(const ComparisonRow& r, bool messages = false) {
  std::uint64_t n = 0;
  for (const par::StageRecord& s : r.record.stages) n += messages ? s.broadcasts : s.broadcastBytes;
  return n;
}

// The figure that shows the method's class, measured on this scene.
std::string measuredFigure(const ComparisonRow& r, int width, int height) {
  const std::string& m = r.what.method;
  const int p = r.what.pes;
  if (isOnePeReference(m)) return "Ts = " + fmt(r.wall, "%.3f") + " s";
  if (m == "image-space")
    return "broadcast " + formatBytes(broadcastCopy(r)) + " to each PE but PE 0, " +
           std::to_string(kindBytes(r, "rays", true)) + " ray messages (P=" + std::to_string(p) + ")";
  if (m == "image-space-cached")
    return (r.cacheHitRatio >= 0.0 ? "hit ratio " + fmt(r.cacheHitRatio, "%.3f") : std::string("no cache used")) + ", " + std::to_string(kindBytes(r, "requests", true)) +
           " requests, " + formatBytes(kindBytes(r, "data")) + " of data fetched (P=" + std::to_string(p) + ")";
  if (m == "object-space" || m == "object")
    return std::to_string(kindBytes(r, "rays", true)) + " ray messages (" + formatBytes(kindBytes(r, "rays")) + ") for " +
           std::to_string(r.rays) + " rays, " + fmt(r.rays ? 1000.0 * double(kindBytes(r, "rays", true)) / double(r.rays) : 0.0) +
           " per 1000 rays; imbalance " + fmt(r.summary.total.imbalance, "%.3f") + " (P=" + std::to_string(p) + ")";
  if (m == "sort-first" || m == "sort-middle")
    return std::to_string(kindBytes(r, "primitives", true)) + " primitive messages, " +
           formatBytes(kindBytes(r, "primitives")) + " (P=" + std::to_string(p) + ")";
  if (m == "sort-last")
    return formatBytes(std::uint64_t(counterTotal(r, "Sort/composite_bytes"))) + " composited, analytic " +
           formatBytes(std::uint64_t(analyticCompositeBytes(width, height, p, r.what.compositor))) + " (P=" + std::to_string(p) + ")";
  return "-";
}

struct MethodScaling {
  std::string method;
  std::vector<std::pair<int, double>> measured;  // (P, T1/Tn)
  std::vector<std::pair<int, double>> measuredSeconds;  // (P, wall s) of every run on the curve
  double measuredOne = 0.0;  // T1: the wall time at P = 1 in this process, 0 when not run
  std::vector<PredictedPoint> predicted;
  // The same record replayed at the measured P on this machine's network (shared-memory): the
  // simulator checked against the measurements, apart from the chosen network's cost.
  std::vector<PredictedPoint> here;
  double serialFraction = std::numeric_limits<double>::quiet_NaN();
  int bestPredictedPes = 1;
  const ComparisonRow* largest = nullptr;  // the run at the largest P
};

// The prediction on this machine's network beside each measurement of the method:
// "P=2: 0.123 s for 0.121 s measured (+2%)".
std::string residuals(const MethodScaling& s) {
  std::string out;
  for (const auto& [p, wall] : s.measuredSeconds)
    for (const PredictedPoint& q : s.here)
      if (q.pes == p && wall > 0.0)
        out += (out.empty() ? "" : "; ") + std::string("P=") + std::to_string(p) + ": " + fmt(q.seconds, "%.4f") + " s for " +
               fmt(wall, "%.4f") + " s measured (" + fmt(100.0 * (q.seconds / wall - 1.0), "%+.0f") + "%)";
  return out.empty() ? "-" : out;
}

// How each stage was replayed at a predicted P: the rule, the strategy and the assumption (or
// why the stage was left out), as `parrender simulate` prints them.
std::string replayNotes(const PredictedPoint& point) {
  std::string items;
  for (const par::StageNote& n : point.notes)
    items += "<li>" + escape(n.stage + ": " + n.rule + (n.schedule.empty() ? "" : " (" + n.schedule + ")") + ": " + n.note) +
             (n.excluded ? " <b>excluded from the prediction</b>" : "") + "</li>";
  return "<details><summary>how each stage was replayed at P = " + std::to_string(point.pes) + "</summary><ul>" + items +
         "</ul></details>";
}

// The rows that trace each method's curve: its first schedule and compositor (a farm's has its
// own section).
bool onCurve(const ComparisonRow& r, const ReportSpec& spec) {
  return r.what.farm.empty() && r.what.schedule == spec.schedules.front() &&
         (r.what.compositor == kNotApplicable || r.what.compositor == raster::compositors().begin()->name);
}

// What a scene's section is made from: the renders every rank takes part in (under mpirun,
// rank 0 holds their figures and images).
struct SceneRuns {
  std::string sceneFile, stem;
  const scene::Scene& scene;
  std::string lighting;
  const scene::RenderPlan& plan;
  int maxThreads = 1;  // the largest --threads value: PEs per rank under mpirun
  Comparison c;
  std::vector<CacheRun> cacheRuns;
  SweepResult sw;
};

// The section's HTML, and its files written under dir: rank 0's part.
std::string sceneSection(const SceneRuns& r, const ReportSpec& spec, const std::filesystem::path& dir,
                         const std::string& relDir) {
  const std::string& sceneFile = r.sceneFile;
  const std::string& stem = r.stem;
  const scene::Scene& scene = r.scene;
  const std::string& lighting = r.lighting;
  const scene::RenderPlan& plan = r.plan;
  const Comparison& c = r.c;
  const SweepResult& sw = r.sw;
  std::filesystem::create_directories(dir / "img");
  writeFileAtomically(dir / "comparison.csv", comparisonCsv(c), "CSV file");
  writeFileAtomically(dir / "comparison.json", comparisonJson(c).dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", "JSON file");

  std::string html = "<section><h2>" + escape(stem) + "</h2>\n<p>" + escape(sceneFile) + ": " +
                     std::to_string(scene.triangles.size()) + " triangles, " + std::to_string(scene.lights.size()) +
                     " punctual lights, " + std::to_string(scene.areaLights.size()) + " emissive triangles; " +
                     escape(lighting) + ". " + std::to_string(spec.width) + "&times;" + std::to_string(spec.height) +
                     " pixels, P in {";
  // The values of P measured (under mpirun: 1 on rank 0 alone, and ranks x each --threads).
  std::set<int> measuredPes;
  for (const ComparisonRow& row : c.rows) measuredPes.insert(row.what.pes);
  for (int p : measuredPes) html += (p == *measuredPes.begin() ? "" : ", ") + std::to_string(p);
  html += "}";
  if (const int ranks = par::ProcessGroup::get().ranks(); ranks > 1)
    html += " across " + std::to_string(ranks) + " ranks launched by mpirun (P = 1 on rank 0 alone)";
  html += ", " + std::to_string(spec.repeat) + " timed runs per combination (median). Files: " + link(relDir + "/comparison.csv", "comparison.csv") + ", " +
          link(relDir + "/comparison.json", "comparison.json") + ".</p>\n";

  // Each method's run at its largest P.
  std::map<std::string, MethodScaling> scaling;
  for (const ComparisonRow& r : c.rows) {
    if (!onCurve(r, spec)) continue;
    MethodScaling& s = scaling[r.what.method];
    s.method = r.what.method;
    if (r.speedup > 0.0) s.measured.emplace_back(r.what.pes, r.speedup);
    s.measuredSeconds.emplace_back(r.what.pes, r.wall);
    if (r.what.pes == 1 && r.what.ranks == 1) s.measuredOne = r.wall;
    if (!s.largest || r.what.pes > s.largest->what.pes) s.largest = &r;
  }

  // The render plan: what the scene calls for, and what each method simulated of it.
  html += "<h3>Render plan</h3><p>The effects the scene calls for (effect analysis), and why:</p><ul>";
  for (scene::Effect e : scene::allEffects()) html += "<li>" + escape(plan.line(e)) + "</li>";
  html += "</ul><p>What each method simulated of them:</p><ul>";
  for (const auto& [method, s] : scaling)
    if (s.largest) html += "<li>" + escape(method) + ": " + escape(s.largest->effects) + "</li>";
  html += "</ul>\n";

  // The classification.
  std::string models;
  for (const std::string& sched : spec.schedules) {
    const ScheduleClass k = classifySchedule(sched);
    models += (models.empty() ? "" : "; ") + sched + ": " + k.model + ", " + k.taskManagement;
  }
  std::vector<std::vector<std::string>> classRows;
  for (const std::string& m : spec.methods) {
    const MethodClass k = classifyMethod(m);
    const auto s = scaling.find(m);
    const ComparisonRow* largest = s != scaling.end() ? s->second.largest : nullptr;
    classRows.push_back({m, std::string(toString(findRenderMethod(m).properties.family)), k.subdivision, k.sortPoint,
                         k.dataManagement, k.definingFigure, largest ? measuredFigure(*largest, spec.width, spec.height) : "-",
                         largest ? checkClaim(m, MeasuredTraffic{largest->what.pes, kindBytes(*largest, "rays", true),
                                                                 kindBytes(*largest, "primitives", true),
                                                                 counterTotal(*largest, "Sort/composite_bytes")})
                                 : "-",
                         k.seedSection});
  }
  html += "<h3>Classification</h3><p>After the seed course, chapters 2&ndash;5. Computational model and task "
          "management of the schedules compared: " + escape(models) + ". Each class's claim about traffic is checked "
          "against the method's run at its largest P: a claim the measurement contradicts says so, and traffic a class "
          "implies that this run did not send (one PE may have had all the work of a small image) is marked not "
          "shown.</p>\n" +
          table({"method", "family", "task subdivision", "sort point", "data management", "defining figure",
                 "measured on this scene", "the class's claim, checked", "seed"},
                classRows, "text");

  // Images and their x8 error against the reference.
  html += "<h3>Images</h3><p>Each method's image at its largest P, and beneath it |image &minus; reference| &times; 8; "
          "the reference is a path-traced render at " + std::to_string(spec.referenceSpp) + " samples per pixel. " +
          (c.mismatches == 0 ? std::string("Every render matched the first of its family bit for bit.")
                             : "<b>" + std::to_string(c.mismatches) + " renders differ from their family's image.</b>") +
          "</p>\n<div>";
  image::writeImage(dir / "img" / "reference.png", c.reference.image);
  html += image(relDir + "/img/reference.png", "reference (path, " + std::to_string(spec.referenceSpp) + " spp)");
  for (const auto& [method, s] : scaling) {
    if (!s.largest) continue;
    image::writeImage(dir / "img" / (method + ".png"), s.largest->image);
    image::writeImage(dir / "img" / (method + "_diff8.png"), differenceImage(s.largest->image, c.reference.image));
    html += image(relDir + "/img/" + method + ".png", method + ", RMSE " + fmt(s.largest->rmse, "%.4f"));
    html += image(relDir + "/img/" + method + "_diff8.png", method + ": error x8");
  }
  html += "</div>\n";

  // The comparison table.
  std::vector<std::vector<std::string>> rows;
  for (const ComparisonRow& r : c.rows) {
    const par::StageSummary& t = r.summary.total;
    const par::KindTraffic all = allTraffic(r);
    std::string kinds;
    for (const par::KindTraffic& k : t.byKind)
      if (k.messages) kinds += (kinds.empty() ? "" : ", ") + k.kind + " " + std::to_string(k.messages);
    rows.push_back({r.what.methodName(), r.what.schedule, r.what.integrator, std::to_string(r.what.pes), fmt(r.wall, "%.4f"),
                    fmt(r.cpu, "%.4f"), r.speedup > 0 ? fmt(r.speedup, "%.2f") : "-",
                    r.speedupSerial > 0 ? fmt(r.speedupSerial, "%.2f") : "-", r.efficiency > 0 ? fmt(r.efficiency, "%.2f") : "-",
                    fmt(t.imbalance, "%.3f"), fmt(t.serialFraction, "%.3f"), std::to_string(all.messages), formatBytes(all.bytes), kinds,
                    t.computeToComm >= 0 ? fmt(t.computeToComm, "%.1f") : "-",
                    r.cacheHitRatio >= 0 ? fmt(r.cacheHitRatio, "%.3f") : "-", fmt(r.rmse, "%.4f"),
                    r.agrees ? r.agreement : "DIFFERS: " + r.agreement});
  }
  std::vector<std::vector<std::string>> skipped;
  for (const SkippedCombination& s : c.skipped) skipped.push_back({s.what, s.reason});
  html += "<h3>Comparison</h3>" +
          table({"method", "schedule", "integrator", "P", "wall s", "CPU s", "T1/Tn", "Ts/Tn", "efficiency", "imbalance",
                 "serial fraction", "messages", "bytes", "messages by kind", "comp/comm", "cache hits", "RMSE", "image"},
                rows) +
          (skipped.empty() ? "" : "<p>Skipped:</p>" + table({"combination", "reason"}, skipped, "text"));
  html += farmSection(c, par::networkByName(spec.network), spec.maxPredictedPes);

  // Speed-up and efficiency against P: measured, predicted, Amdahl.
  std::fprintf(stderr, "report: %s: predicting to %d PEs on %s\n", stem.c_str(), spec.maxPredictedPes, spec.network.c_str());
  const par::NetworkModel& network = par::networkByName(spec.network);
  const std::vector<int> predictedPes = powersOfTwo(spec.maxPredictedPes);
  nlohmann::json scalingData = nlohmann::json::array();
  for (auto& [method, s] : scaling) {
    if (isOnePeReference(method) || !s.largest) continue;
    s.predicted = predictScaling(s.largest->record, network, predictedPes, s.measuredOne);
    // Every measured P (and 1, the baseline) on this machine's network, beside the measurements.
    std::vector<int> atMeasured = {1};
    for (const auto& [p, wall] : s.measuredSeconds) atMeasured.push_back(p);
    std::sort(atMeasured.begin(), atMeasured.end());
    atMeasured.erase(std::unique(atMeasured.begin(), atMeasured.end()), atMeasured.end());
    s.here = predictScaling(s.largest->record, par::networkByName("shared-memory"), atMeasured, s.measuredOne);
    s.serialFraction = fittedSerialFraction(s.measured);
    double best = 0.0;
    for (const PredictedPoint& p : s.predicted) {
      scalingData.push_back({{"method", method}, {"P", p.pes}, {"speedup", p.speedup}, {"efficiency", p.efficiency},
                             {"series", "predicted (" + spec.network + ")"}});
      if (p.speedup > best) best = p.speedup, s.bestPredictedPes = p.pes;
    }
    for (const auto& [p, speedup] : s.measured)
      scalingData.push_back({{"method", method}, {"P", p}, {"speedup", speedup}, {"efficiency", speedup / p}, {"series", "measured"}});
    if (std::isfinite(s.serialFraction))
      for (int p : predictedPes)
        scalingData.push_back({{"method", method}, {"P", p}, {"speedup", amdahlSpeedup(s.serialFraction, p)},
                               {"efficiency", amdahlSpeedup(s.serialFraction, p) / p}, {"series", "Amdahl fit"}});
    for (const PredictedPoint& p : s.predicted)
      if (p.pes == s.bestPredictedPes)
        scalingData.push_back({{"method", method}, {"P", p.pes}, {"speedup", p.speedup}, {"efficiency", p.efficiency},
                               {"series", "best P"}});
  }
  auto scalingSpec = [](const char* field, bool logY) {
    const nlohmann::json x = {{"field", "P"}, {"type", "quantitative"}, {"scale", {{"type", "log"}, {"base", 2}}}};
    nlohmann::json y = {{"field", field}, {"type", "quantitative"}};
    if (logY) y["scale"] = {{"type", "log"}};
    const nlohmann::json color = {{"field", "method"}, {"type", "nominal"}};
    return nlohmann::json{
        {"layer",
         {{{"transform", {{{"filter", "datum.series != 'measured' && datum.series != 'best P'"}}}},
           {"mark", {{"type", "line"}, {"clip", true}}},
           {"encoding", {{"x", x}, {"y", y}, {"color", color}, {"strokeDash", {{"field", "series"}, {"type", "nominal"}}}}}},
          {{"transform", {{{"filter", "datum.series == 'measured'"}}}},
           {"mark", {{"type", "point"}, {"filled", true}, {"size", 70}}},
           {"encoding", {{"x", x}, {"y", y}, {"color", color}, {"tooltip", {{{"field", "method"}}, {{"field", "P"}}, {{"field", field}}}}}}},
          {{"transform", {{{"filter", "datum.series == 'best P'"}}}},
           {"mark", {{"type", "point"}, {"shape", "diamond"}, {"size", 160}, {"filled", true}}},
           {"encoding", {{"x", x}, {"y", y}, {"color", color}, {"tooltip", {{{"field", "method"}}, {{"field", "P"}}}}}}}}}};
  };
  html += "<h3>Speed-up and efficiency against P</h3><p>Dots: measured (T1/Tn). Solid and dashed lines: the "
          "simulator replaying each method's largest-P run at P = 1 &hellip; " + std::to_string(predictedPes.back()) +
          " on the " + escape(spec.network) + " network (" + escape(std::string(network.description)) +
          "), its speed-ups against the measured T1 like the dots', and Amdahl's law with the Karp&ndash;Flatt serial "
          "fraction fitted to the measured points. Diamonds: the best predicted P. The table checks the simulator against "
          "the measurements: the same record replayed at each measured P on this machine's network (shared-memory), "
          "beside the measured time (predicted / measured &minus; 1).</p>\n";
  html += chart(dir, relDir, "speedup", scalingSpec("speedup", true), scalingData, "Speed-up against P");
  html += chart(dir, relDir, "efficiency", scalingSpec("efficiency", false), scalingData, "Efficiency against P");
  std::vector<std::vector<std::string>> fitRows;
  for (const auto& [method, s] : scaling) {
    if (isOnePeReference(method) || s.predicted.empty()) continue;
    fitRows.push_back({method, residuals(s), std::isfinite(s.serialFraction) ? fmt(s.serialFraction, "%.4f") : "-",
                       std::isfinite(s.serialFraction) && s.serialFraction > 0 ? fmt(1.0 / s.serialFraction, "%.1f") : "-",
                       std::to_string(s.bestPredictedPes), fmt(s.predicted.back().speedup, "%.3g"),
                       fmt(s.predicted.back().efficiency, "%.3f"), fmt(s.predicted.back().seconds, "%.4f")});
  }
  html += table({"method", "replayed at the measured P (shared-memory)", "Karp-Flatt serial fraction", "Amdahl bound 1/f", "best predicted P",
                 "predicted speed-up at " + std::to_string(predictedPes.back()),
                 "predicted efficiency", "predicted seconds"},
                fitRows);

  // Per-PE time and the timeline of the chosen run.
  const ComparisonRow* chosen = nullptr;
  if (auto s = scaling.find(spec.timelineMethod); s != scaling.end()) chosen = s->second.largest;
  if (!chosen)
    for (const auto& [method, s] : scaling)
      if (s.largest && (!chosen || s.largest->what.pes > chosen->what.pes)) chosen = s.largest;
  if (chosen) {
    par::writeRunRecord(chosen->record, dir / "timeline_metrics.json");
    par::writeChromeTrace(chosen->record, dir / "timeline.trace.json");
    nlohmann::json perPe = nlohmann::json::array();
    const std::vector<par::PeStageRecord> totals = par::peTotals(chosen->record);
    for (std::size_t p = 0; p < totals.size(); ++p) {
      const par::PeStageRecord& t = totals[p];
      const double other = std::max(0.0, t.idleSeconds - t.syncWaitSeconds - t.messageWaitSeconds);
      perPe.push_back({{"pe", p}, {"state", "computing"}, {"seconds", std::max(0.0, t.busySeconds - t.sendReceiveSeconds)}});
      perPe.push_back({{"pe", p}, {"state", "communicating"}, {"seconds", t.sendReceiveSeconds + t.messageWaitSeconds}});
      perPe.push_back({{"pe", p}, {"state", "waiting at synchronisation"}, {"seconds", t.syncWaitSeconds}});
      perPe.push_back({{"pe", p}, {"state", "idle"}, {"seconds", other}});
    }
    // The record keeps spans stage by stage and PE by PE; the chart shows the run's first ones in time.
    std::vector<par::TaskSpan> timeline = chosen->record.timeline;
    std::stable_sort(timeline.begin(), timeline.end(), [](const par::TaskSpan& x, const par::TaskSpan& y) { return x.start < y.start; });
    nlohmann::json spans = nlohmann::json::array();
    for (const par::TaskSpan& s : timeline) {
      if (spans.size() >= kMaxTimelineSpans) break;
      const std::string& stage = chosen->record.stages[std::size_t(s.stage)].name;
      const std::string what = s.task == par::kMessageSpan ? std::string("message handler")
                               : s.task == par::kSetupSpan ? stage + " set-up"
                                                           : stage;
      spans.push_back({{"pe", s.pe}, {"start", s.start}, {"end", s.end}, {"what", what}, {"task", s.task},
                       {"messagesSent", s.messagesSent}});
    }
    const nlohmann::json peAxis = {{"field", "pe"}, {"type", "ordinal"}, {"title", "PE"}};
    html += "<h3>Per-PE time and timeline: " + escape(chosen->what.label()) + "</h3><p>Busy, communicating (inside "
            "channel calls or waiting on an empty mailbox), waiting at the end-of-stage synchronisation and otherwise idle, "
            "per PE; then every task, message handler and set-up on its PE. The run's record: " +
            link(relDir + "/timeline_metrics.json", "timeline_metrics.json") +
            "; its Chrome trace (Perfetto, chrome://tracing): " + link(relDir + "/timeline.trace.json", "timeline.trace.json") +
            ".</p>\n";
    html += chart(dir, relDir, "per_pe",
                  {{"mark", "bar"},
                   {"height", 40 + 24 * int(totals.size())},
                   {"encoding", {{"y", peAxis}, {"x", {{"field", "seconds"}, {"type", "quantitative"}, {"stack", true}}},
                                 {"color", {{"field", "state"}, {"type", "nominal"}}}, {"tooltip", {{{"field", "state"}}, {{"field", "seconds"}}}}}}},
                  perPe, "Time per PE by state");
    html += chart(dir, relDir, "gantt",
                  {{"mark", "bar"},
                   {"width", 900},
                   {"height", 40 + 30 * int(totals.size())},
                   {"encoding", {{"y", peAxis},
                                 {"x", {{"field", "start"}, {"type", "quantitative"}, {"title", "seconds"}}},
                                 {"x2", {{"field", "end"}}},
                                 {"color", {{"field", "what"}, {"type", "nominal"}}},
                                 {"tooltip", {{{"field", "what"}}, {{"field", "task"}}, {{"field", "start"}}, {{"field", "end"}}, {{"field", "messagesSent"}}}}}}},
                  spans,
                  "Timeline, one row per PE" + std::string(timeline.size() > kMaxTimelineSpans
                                                               ? " (the first " + std::to_string(kMaxTimelineSpans) + " spans in time)"
                                                               : ""));
  }

  // Communication volume by method and kind, and sort-last's against the analytic volume.
  nlohmann::json volume = nlohmann::json::array(), analytic = nlohmann::json::array();
  for (const ComparisonRow& r : c.rows) {
    if (!onCurve(r, spec)) continue;
    for (const par::KindTraffic& k : r.summary.total.byKind)
      if (k.bytes > 0)
        volume.push_back({{"run", r.what.method + " P=" + std::to_string(r.what.pes)}, {"kind", k.kind}, {"bytes", k.bytes},
                          {"messages", k.messages}});
    if (r.what.method == "sort-last" && r.what.pes > 1 && !spec.settings.raster.sparse) {
      analytic.push_back({{"P", r.what.pes}, {"source", "measured"}, {"bytes", counterTotal(r, "Sort/composite_bytes")}});
      analytic.push_back({{"P", r.what.pes}, {"source", "analytic b A (P - 1) + h M"},
                          {"bytes", analyticCompositeBytes(spec.width, spec.height, r.what.pes, spec.settings.raster.compositor)}});
    }
  }
  html += "<h3>Communication volume</h3><p>Bytes between PEs by kind: tasks (scheduling), primitives, rays, pixels, "
          "broadcasts (replicated data, once per receiving PE), results (image assembly), requests and data (the data "
          "manager).</p>\n";
  html += chart(dir, relDir, "communication",
                {{"mark", "bar"},
                 {"width", 700},
                 {"encoding", {{"x", {{"field", "run"}, {"type", "nominal"}, {"sort", nullptr}}},
                               {"y", {{"field", "bytes"}, {"type", "quantitative"}, {"stack", true}}},
                               {"color", {{"field", "kind"}, {"type", "nominal"}}},
                               {"tooltip", {{{"field", "run"}}, {{"field", "kind"}}, {{"field", "bytes"}}, {{"field", "messages"}}}}}}},
                volume, "Bytes sent by kind");
  if (!analytic.empty())
    html += chart(dir, relDir, "composite_analytic",
                  {{"mark", "bar"},
                   {"width", 300},
                   {"encoding", {{"x", {{"field", "P"}, {"type", "ordinal"}}},
                                 {"xOffset", {{"field", "source"}}},
                                 {"y", {{"field", "bytes"}, {"type", "quantitative"}}},
                                 {"color", {{"field", "source"}, {"type", "nominal"}}},
                                 {"tooltip", {{{"field", "source"}}, {{"field", "bytes"}}}}}}},
                  analytic, "Sort-last compositing, measured against the analytic volume");

  // Data management: the cached tracer's hit ratio against its cache size.
  if (std::find(spec.methods.begin(), spec.methods.end(), "image-space-cached") != spec.methods.end()) {
    const auto cached = scaling.find("image-space-cached");
    const image::Image* expected = cached != scaling.end() && cached->second.largest ? &cached->second.largest->image : nullptr;
    html += cacheSweepSection(spec, r.cacheRuns, everyRank(r.maxThreads).pes, expected, dir, relDir);
  }

  // Accuracy against time: the photon map against the path tracer.
  nlohmann::json accuracy = nlohmann::json::array();
  for (const SweepRow& r : sw.rows)
    accuracy.push_back({{"integrator", r.integrator}, {"setting", r.setting + " " + formatValue(r.value)},
                        {"cpuSeconds", r.timed.cpuSeconds}, {"rmse", r.error.rmse}});
  std::string toTarget;
  for (const auto& [integrator, t] : sw.cpuSecondsToTarget)
    toTarget += (toTarget.empty() ? "" : ", ") + integrator + " " + (t ? fmt(*t, "%.3g") + " CPU s" : std::string("not reached"));
  html += "<h3>Accuracy against time</h3><p>The photon map (" +
          std::to_string(spec.settings.ray.photonmap.globalPhotons) + " global and " +
          std::to_string(spec.settings.ray.photonmap.causticPhotons) + " caustic photons, spp " +
          std::to_string(spec.photonSpp.front()) + " &hellip; " + std::to_string(spec.photonSpp.back()) +
          ") against the path tracer (spp " +
          std::to_string(spec.pathSpp.front()) + " &hellip; " + std::to_string(spec.pathSpp.back()) +
          "), RMSE against the reference. Time each needs for RMSE " + fmt(sw.targetRmse, "%.4f") + ": " + escape(toTarget) +
          ".</p>\n";
  html += chart(dir, relDir, "accuracy",
                {{"mark", {{"type", "line"}, {"point", true}}},
                 {"encoding", {{"x", {{"field", "cpuSeconds"}, {"type", "quantitative"}, {"scale", {{"type", "log"}}}, {"title", "CPU seconds"}}},
                               {"y", {{"field", "rmse"}, {"type", "quantitative"}, {"scale", {{"type", "log"}}}, {"title", "RMSE"}}},
                               {"color", {{"field", "integrator"}, {"type", "nominal"}}},
                               {"tooltip", {{{"field", "integrator"}}, {{"field", "setting"}}, {{"field", "cpuSeconds"}}, {{"field", "rmse"}}}}}}},
                accuracy, "RMSE against CPU time");

  // The verdict.
  // Only among rows whose image agrees with their family's: a faster wrong image wins nothing.
  html += "<h3>Verdict</h3><div class=\"verdict\">" +
          (c.mismatches > 0 ? "<p><b>" + std::to_string(c.mismatches) +
                                  " renders differ from their family's image: none of them is chosen as the fastest below, "
                                  "and the report command fails.</b></p>"
                            : std::string()) +
          "<ul>";
  for (int p : measuredPes) {
    const ComparisonRow* fastest = nullptr;
    for (const ComparisonRow& r : c.rows)
      if (r.agrees && r.what.pes == p && (!fastest || r.wall < fastest->wall)) fastest = &r;
    if (!fastest) continue;
    html += "<li>At P = " + std::to_string(p) + " the fastest is <b>" + escape(fastest->what.label()) + "</b>, " +
            fmt(fastest->wall, "%.4f") + " s (efficiency " +
            (fastest->efficiency > 0 ? fmt(fastest->efficiency, "%.2f") : std::string("-")) + ", imbalance " +
            fmt(fastest->summary.total.imbalance, "%.3f") + ").";
    for (MethodFamily family : {MethodFamily::Ray, MethodFamily::Raster}) {
      const ComparisonRow* best = nullptr;
      for (const ComparisonRow& r : c.rows)
        if (r.agrees && r.what.pes == p && r.what.family == family && (!best || r.wall < best->wall)) best = &r;
      if (best && best != fastest)
        html += " Fastest " + escape(std::string(toString(family))) + ": " + escape(best->what.methodName()) + ", " +
                fmt(best->wall, "%.4f") + " s.";
    }
    html += "</li>";
  }
  // At the largest predicted P: the fastest overall and per family, and per method what the
  // prediction rests on - the replicated data every PE must receive first, over this network.
  auto predictedFastest = [&](std::optional<MethodFamily> family) {
    const MethodScaling* best = nullptr;
    for (const auto& [method, s] : scaling)
      if (!s.predicted.empty() && s.largest->agrees && (!family || s.largest->what.family == *family) &&
          (!best || s.predicted.back().seconds < best->predicted.back().seconds))
        best = &s;
    return best;
  };
  if (const MethodScaling* top = predictedFastest(std::nullopt)) {
    const int topP = top->predicted.back().pes;
    html += "<li>At " + std::to_string(topP) + " PEs on " + escape(spec.network) + " the simulator predicts <b>" +
            escape(top->method) + "</b> fastest, " + fmt(top->predicted.back().seconds, "%.4f") + " s";
    for (MethodFamily family : {MethodFamily::Ray, MethodFamily::Raster})
      if (const MethodScaling* best = predictedFastest(family); best && best != top)
        html += "; fastest " + escape(std::string(toString(family))) + ": " + escape(best->method) + ", " +
                fmt(best->predicted.back().seconds, "%.4f") + " s";
    html += ". Per method:<ul>";
    for (const auto& [method, s] : scaling) {
      if (s.predicted.empty()) continue;
      const ComparisonRow& r = *s.largest;
      const PredictedPoint& last = s.predicted.back();
      const PredictedPoint* bestPoint = &s.predicted.front();
      for (const PredictedPoint& q : s.predicted)
        if (q.pes == s.bestPredictedPes) bestPoint = &q;
      const std::uint64_t perPeBytes = broadcastCopy(r);
      const std::uint64_t perPeMessages = broadcastCopy(r, true);
      const std::uint64_t dataBytes = allTraffic(r).bytes - kindBytes(r, "broadcasts") - kindBytes(r, "tasks");
      html += "<li>" + escape(method) + ": " + fmt(last.seconds, "%.4f") + " s at " + std::to_string(topP) +
              " PEs (speed-up " + fmt(last.speedup, "%.3g") + ", efficiency " + fmt(last.efficiency, "%.3f") + ", imbalance " +
              fmt(last.imbalance, "%.2f") + "); best at P = " + std::to_string(bestPoint->pes) + ", " +
              fmt(bestPoint->seconds, "%.4f") + " s. Each PE but PE 0 first receives " + formatBytes(perPeBytes) +
              " of replicated data, " + fmt(network.broadcastArrival(topP - 1, topP, perPeMessages, perPeBytes), "%.3g") +
              " s until the last of " + std::to_string(topP) + " PEs has it; measured at P = " + std::to_string(r.what.pes) + ", " +
              formatBytes(dataBytes) + " of other data between PEs, computation/communication " +
              (r.summary.total.computeToComm >= 0 ? fmt(r.summary.total.computeToComm, "%.1f") : std::string("- (no messages)")) +
              ", serial fraction " + fmt(r.summary.total.serialFraction, "%.3f") + " (stages on one PE by design), "
              "Karp&ndash;Flatt serial fraction " +
              (std::isfinite(s.serialFraction) ? fmt(s.serialFraction, "%.3f") : std::string("-")) +
              "; replayed at the measured P on shared memory: " + escape(residuals(s)) + "." + replayNotes(last) + "</li>";
    }
    html += "</ul></li>";
  }
  html += "</ul></div></section>\n";
  return html;
}


}  // namespace

SceneSection sceneReport(const std::string& sceneFile, const ReportSpec& spec, const std::filesystem::path& dir,
                         const std::string& relDir) {
  const bool holds = holdsResults();  // under mpirun, rank 0 prints and writes
  const std::string stem = std::filesystem::path(sceneFile).stem().string();
  if (holds) std::fprintf(stderr, "report: %s: loading\n", stem.c_str());
  scene::Scene scene = loadScene(sceneFile, spec.lighting);
  const std::string lighting = applyLighting(scene, spec.lighting);
  const scene::Camera camera = scene::selectCamera(scene, spec.camera, float(spec.width) / float(spec.height));
  const scene::RenderPlan plan = scene::analyzeEffects(scene, &camera);
  const RenderInput input{scene, camera, plan, spec.width, spec.height};
  const int maxThreads = *std::max_element(spec.threads.begin(), spec.threads.end());
  SceneRuns runs{sceneFile, stem, scene, lighting, plan, maxThreads, {}, {}, {}};

  // The renders, every rank taking part in each.
  ComparisonSpec cs;
  cs.methods = spec.methods;
  cs.schedules = spec.schedules;
  cs.integrators = {"path"};
  cs.compositors = {raster::compositors().begin()->name};
  cs.threads = spec.threads;
  cs.repeat = spec.repeat;
  cs.settings = spec.settings;
  cs.farm = spec.farm;
  cs.referenceSettings = ReferenceSettings{sceneFile, spec.camera, "", spec.lighting, spec.referenceSpp, 16,
                                           spec.settings.ray.seed, spec.referenceDir, false, "image-space",
                                           everyRank(maxThreads), {}};
  if (holds) std::fprintf(stderr, "report: %s: comparison run\n", stem.c_str());
  runs.c = runComparison(cs, input);
  // Data management: the cached tracer's hit ratio against its cache size.
  if (std::find(spec.methods.begin(), spec.methods.end(), "image-space-cached") != spec.methods.end())
    runs.cacheRuns = runCacheSweep(spec, input, maxThreads);
  // Accuracy against time: the photon map against the path tracer.
  if (holds) std::fprintf(stderr, "report: %s: accuracy sweep\n", stem.c_str());
  SweepSpec sweep;
  sweep.scene = sceneFile;
  sweep.width = spec.width;
  sweep.height = spec.height;
  sweep.camera = spec.camera;
  sweep.threads = maxThreads;
  sweep.vary = "spp";
  sweep.values.assign(spec.photonSpp.begin(), spec.photonSpp.end());
  sweep.integrators = {"photonmap", "path"};
  sweep.pathSpp = spec.pathSpp;
  sweep.pathSppGiven = true;
  sweep.spp = spec.settings.ray.spp;
  sweep.maxDepth = spec.settings.ray.maxDepth;
  sweep.seed = spec.settings.ray.seed;
  sweep.referenceSpp = spec.referenceSpp;
  sweep.referenceDepth = 16;
  sweep.referenceDir = spec.referenceDir.string();
  sweep.lighting = spec.lighting;
  sweep.photonmap = spec.settings.ray.photonmap;
  runs.sw = runSweep(sweep);

  // The section, written by rank 0 alone while the other ranks wait.
  std::string html;
  par::ProcessGroup::get().onRank0Alone("rank 0 writing the report's section on " + stem, [&] {
    html = sceneSection(runs, spec, dir, relDir);
    return par::Bytes();
  });
  return {html, runs.c.mismatches};
}

}  // namespace pr::cli::report
