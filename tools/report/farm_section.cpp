// The report's render-farm section (see farm_section.h).
#include "tools/report/farm_section.h"

#include <algorithm>
#include <set>
#include <vector>

#include "common/util/memory_limit.h"
#include "tools/compare/comparison_output.h"
#include "tools/farm_render.h"
#include "tools/report/html.h"

namespace pr::cli::report {

namespace {

std::string fmt(double v, const char* format = "%.3g") { return formatNumber(v, format); }

// Image-space as SPMD stages on the same ranks and PEs per rank as the farm row, or nullptr.
const ComparisonRow* spmdBeside(const Comparison& c, const ComparisonRow& farm) {
  const Combination& f = farm.what;
  for (const ComparisonRow& r : c.rows) {
    const Combination& o = r.what;
    if (o.farm.empty() && o.method == f.method && o.schedule == f.schedule && o.integrator == f.integrator &&
        o.ranks == f.ranks && o.pesPerProcess() == f.pesPerProcess())
      return &r;
  }
  return nullptr;
}

}  // namespace

std::string farmSection(const Comparison& c, const par::NetworkModel& network, int maxServers) {
  std::vector<const ComparisonRow*> farms;
  for (const ComparisonRow& r : c.rows)
    if (r.record.farm) farms.push_back(&r);
  if (farms.empty()) return {};
  const par::FarmRecord& first = *farms.front()->record.farm;
  std::string html =
      "<h3>The render farm</h3><p>Image-space as the seed's photon-map farm (Jensen): rank 0, the master, traces nothing "
      "and hands out jobs (" + escape(first.jobShape) + ") in the order of " + escape(first.schedule) +
      "; every other rank is a server that runs the pre-passes (" + escape(first.prepass) +
      "), renders each job with its own PEs under the row's schedule and sends the result back. Beside each farm, "
      "image-space on the same ranks as SPMD stages (the master's rank then a rank of PEs too). Servers say they are "
      "alive while they work; one silent for the deadline (" + fmt(first.deadlineSeconds, "%.1f") +
      " s) would be lost and its jobs handed on, which the report, needing every rank for its later renders, counts as a "
      "failure.</p>\n";

  std::vector<std::vector<std::string>> rows;
  for (const ComparisonRow* r : farms) {
    const ComparisonRow* spmd = spmdBeside(c, *r);
    const par::FarmRecord& f = *r->record.farm;
    std::uint64_t resultBytes = 0;
    for (const par::FarmJobRecord& j : f.jobs) resultBytes += j.resultBytes;
    rows.push_back({r->what.label(), std::to_string(f.servers.size()), std::to_string(f.jobs.size()), fmt(r->wall, "%.4f"),
                    r->speedupSerial > 0 ? fmt(r->speedupSerial, "%.2f") : "-",
                    spmd ? spmd->what.label() + ": " + fmt(spmd->wall, "%.4f") + " s" : "-",
                    spmd && r->wall > 0 ? fmt(spmd->wall / r->wall, "%.2f") : "-", formatBytes(resultBytes),
                    r->agrees ? r->agreement : "DIFFERS: " + r->agreement});
  }
  html += table({"farm", "servers", "jobs", "wall s", "Ts/Tn", "SPMD image-space, same ranks", "SPMD/farm", "result bytes",
                 "image"},
                rows);

  // Every server of the farm at the largest P: how the master's demand spread the jobs.
  const ComparisonRow& largest = **std::max_element(farms.begin(), farms.end(), [](const ComparisonRow* a, const ComparisonRow* b) {
    return a->what.pes < b->what.pes;
  });
  const par::FarmRecord& f = *largest.record.farm;
  std::vector<std::vector<std::string>> servers;
  for (const par::FarmServerRecord& s : f.servers)
    servers.push_back({std::to_string(s.rank), std::to_string(s.pes), std::to_string(s.jobs.size()), fmt(s.prepareSeconds, "%.4f"),
                       fmt(s.busySeconds, "%.4f"), fmt(s.idleSeconds, "%.4f"), fmt(s.cpuSeconds, "%.4f"),
                       s.lost() ? "at " + fmt(s.lostAtSeconds, "%.2f") + " s, " + std::to_string(s.handedOn.size()) + " jobs handed on"
                                : "no",
                       std::to_string(s.lateResults)});
  html += "<p>" + escape(largest.what.label()) + ", its median run, server by server:</p>" +
          table({"server rank", "PEs", "jobs", "pre-passes s", "busy s", "idle s", "CPU s", "lost", "late results"}, servers);

  // The simulator's replay of that record at other numbers of servers.
  // Up to one server per job: more would have nothing to do.
  const int most = std::min(maxServers, int(f.jobs.size()));
  std::set<int> counts = {int(f.servers.size())};
  for (int s = 1; s <= most; s *= 2) counts.insert(s);
  if (most >= 30) counts.insert(30);  // the seed's farm: 30 servers
  const par::FarmPrediction one = predictFarmRun(largest.record, 1, network, f.schedule, {});
  const double measuredJobs = largest.record.stages[1].wallSeconds;
  std::vector<std::vector<std::string>> predicted;
  for (int s : counts) {
    const par::FarmPrediction p = predictFarmRun(largest.record, s, network, f.schedule, {});
    const bool measured = s == int(f.servers.size());
    predicted.push_back({std::to_string(s) + (measured ? " (measured: jobs " + fmt(measuredJobs, "%.4f") + " s, " +
                                                             fmt(measuredJobs > 0 ? 100.0 * (p.jobsSeconds - measuredJobs) / measuredJobs : 0.0, "%+.1f") +
                                                             "% off)"
                                                       : ""),
                         fmt(p.makespanSeconds, "%.4f"), fmt(p.jobsSeconds, "%.4f"),
                         fmt(p.jobsSeconds > 0 ? one.jobsSeconds / p.jobsSeconds : 0.0, "%.2f"), fmt(p.masterLinkSeconds, "%.4f")});
  }
  html += "<p>The simulator's replay of that record (each job at the time its server measured, handed out by the same "
          "schedule, results into the master one after another over its link on " + escape(std::string(network.name)) +
          "; every server first runs the pre-passes, the recorded mean" +
          (f.prepass == "shared" ? std::string(", kept at its recorded time though each server's share would shrink: an upper bound")
                                 : std::string()) +
          "), up to one server per job:</p>" +
          table({"servers", "makespan s", "jobs s", "jobs speed-up", "master link s"}, predicted);
  return html;
}

}  // namespace pr::cli::report
