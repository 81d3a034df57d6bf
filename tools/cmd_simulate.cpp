// parrender simulate: predicts what a recorded run (or a cost table) would do at other P and
// on other networks, with the same scheduling strategies in virtual time
// (common/parallel/simulator.h). Prints one row per P: makespan, speed-up, efficiency,
// imbalance, communication volume, Karp-Flatt serial fraction; then the P beyond which adding
// PEs stops helping.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/parallel/farm/farm.h"
#include "common/parallel/farm/farm_replay.h"
#include "common/parallel/metrics.h"
#include "common/parallel/run_options.h"
#include "common/parallel/simulator.h"
#include "common/util/error.h"
#include "tools/commands.h"
#include "tools/farm_render.h"

namespace pr::cli {
namespace {

constexpr int kMaxSimulatedPes = 1024;

// "1,2,4,...,1024": numbers, and "..." continuing the progression of the two numbers before it
// (geometric when their ratio is a whole number > 1, else arithmetic) up to the number after it.
std::vector<int> parsePesList(const std::string& text) {
  std::vector<int> pes;
  std::vector<std::string> tokens;
  std::stringstream in(text);
  for (std::string token; std::getline(in, token, ',');) tokens.push_back(token);
  auto bad = [&](const std::string& why) { throw InputError("--pes '" + text + "': " + why); };
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& t = tokens[i];
    if (t == "...") {
      if (pes.size() < 2 || i + 1 >= tokens.size()) bad("'...' needs two numbers before it and one after it");
      const int a = pes[pes.size() - 2], b = pes.back();
      int limit = 0;
      try {
        limit = std::stoi(tokens[i + 1]);
      } catch (const std::exception&) {
        bad("'" + tokens[i + 1] + "' is not a number");
      }
      if (b <= a) bad("'...' needs an increasing progression");
      const bool geometric = b % a == 0 && b / a > 1;
      for (long next = geometric ? long(b) * (b / a) : 2L * b - a; next < limit;
           next = geometric ? next * (b / a) : next + (b - a))
        pes.push_back(static_cast<int>(next));
      continue;
    }
    std::size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(t, &used);
    } catch (const std::exception&) {
      bad("'" + t + "' is not a number");
    }
    if (used != t.size()) bad("'" + t + "' is not a number");
    if (value < 1 || value > kMaxSimulatedPes) bad("P must be in [1, " + std::to_string(kMaxSimulatedPes) + "], got " + t);
    pes.push_back(value);
  }
  if (pes.empty()) bad("no P given");
  return pes;
}

struct SimulateArgs {
  std::string input;
  std::string pes = "1,2,4,...,1024";
  std::string network = "shared-memory";
  par::ScheduleOptions schedule;
  bool scheduleGiven = false;
};

// Seconds from a stage's start until the last PE has its copy of the stage's broadcast data,
// summed over the stages of a predicted run (NetworkModel::broadcastArrival).
double broadcastSeconds(const par::RunRecord& predicted, const par::NetworkModel& network) {
  double total = 0.0;
  for (const par::StageRecord& s : predicted.stages) {
    const par::PeStageRecord& last = s.pes.back();
    total += network.broadcastArrival(predicted.pes - 1, predicted.pes, last.broadcastsReceived, last.broadcastBytesReceived);
  }
  return total;
}

// The run record in `file` when it is one of a farm (render --farm), else nothing.
// A run record (JSON) is read once: a farm's goes to simulateFarm, any other becomes the
// workload, as readWorkload makes it of a record or a cost table.
std::optional<par::RunRecord> runRecordIn(const std::string& file) {
  std::ifstream in(file);
  char first = 0;
  in >> first;
  if (first != '{') return std::nullopt;
  return par::readRunRecord(file);
}

// A farm's record at other numbers of servers (common/parallel/farm/farm_replay.h): --pes
// counts servers, each with the recorded servers' PEs.
void simulateFarm(const par::RunRecord& record, const std::vector<int>& serversList, const par::NetworkModel& network,
                  const SimulateArgs& args) {
  const par::FarmRecord& farm = *record.farm;
  if (record.stages.size() < 2) throw InputError(args.input + ": a farm record has its jobs as its second stage");
  const par::StageRecord& jobs = record.stages[1];
  const std::string schedule = args.scheduleGiven ? args.schedule.schedule : farm.schedule;
  const int pes = farm.servers.empty() ? 1 : farm.servers.front().pes;
  std::printf("recorded farm: %zu servers of %d PE%s, %zu jobs (%s) in the order of %s; jobs stage %.6f s, farm %.6f s\n",
              farm.servers.size(), pes, pes == 1 ? "" : "s", farm.jobs.size(), farm.jobShape.c_str(), farm.schedule.c_str(),
              jobs.wallSeconds, farm.wallSeconds);
  std::printf("schedule %s; network %s (%s); results reach the master one after another over its link\n",
              schedule.c_str(), std::string(network.name).c_str(), std::string(network.description).c_str());
  const auto predictAt = [&](int servers) { return predictFarmRun(record, servers, network, schedule, args.schedule.params); };
  const par::FarmPrediction one = predictAt(1);
  const par::FarmPrediction recorded = predictAt(int(farm.servers.size()));
  std::printf("at the recorded %zu servers: jobs stage predicted %.6f s, measured %.6f s (%+.1f%%)\n\n", farm.servers.size(),
              recorded.jobsSeconds, jobs.wallSeconds,
              jobs.wallSeconds > 0.0 ? 100.0 * (recorded.jobsSeconds - jobs.wallSeconds) / jobs.wallSeconds : 0.0);
  std::printf("%8s %14s %12s %14s %16s\n", "servers", "makespan s", "jobs s", "jobs speed-up", "master link s");
  for (int servers : serversList) {
    const par::FarmPrediction p = predictAt(servers);
    std::printf("%8d %14.6f %12.6f %14.3f %16.6f\n", servers, p.makespanSeconds, p.jobsSeconds,
                p.jobsSeconds > 0.0 ? one.jobsSeconds / p.jobsSeconds : 0.0, p.masterLinkSeconds);
  }
  std::printf("\nmakespan: every server's pre-passes (the recorded mean, %.6f s: each server runs them itself) and the jobs\n",
              one.prepareSeconds);
}

void runSimulate(const SimulateArgs& args) {
  const par::NetworkModel& network = par::networkByName(args.network);
  const std::vector<int> pesList = parsePesList(args.pes);
  const std::optional<par::RunRecord> record = runRecordIn(args.input);
  if (record && record->farm) {
    simulateFarm(*record, pesList, network, args);
    return;
  }
  const par::Workload workload = record ? par::workloadFromRecord(*record, "'" + args.input + "'") : par::readWorkload(args.input);
  const bool fromRecord = workload.recordedPes > 0;

  // The stages that ran under the run's schedule keep it (and the recorded grain) unless the
  // command line names another; a cost table uses the command line's.
  const std::string schedule = args.scheduleGiven || !fromRecord ? args.schedule.schedule : "";
  par::ScheduleParams params = args.schedule.params;
  if (!args.scheduleGiven && fromRecord) params.grain = workload.grain;
  std::size_t tasks = 0;
  double work = 0.0, handlerWork = 0.0, setupWork = 0.0, gaps = 0.0;
  for (const par::SimStage& s : workload.stages) {
    tasks += s.costs.size();
    for (double c : s.costs) work += c;
    for (const par::HandlerLoad& h : s.handlers) handlerWork += h.seconds;
    for (const par::SetupLoad& load : s.setups) setupWork += load.seconds;
    gaps += s.gapBeforeSeconds;
  }
  if (fromRecord)
    std::printf("recorded run: P = %d, schedule %s, wall %.6f s; %zu stages, %zu tasks, %.6f s of task work\n",
                workload.recordedPes, workload.schedule.c_str(), workload.recordedWallSeconds, workload.stages.size(),
                tasks, work);
  else
    std::printf("cost table: %zu tasks, %.6f s of task work\n", tasks, work);
  if (handlerWork > 0.0)
    std::printf("message handlers: %.6f s of recorded handler work, charged on the PEs alongside the tasks\n",
                handlerWork);
  if (setupWork > 0.0)
    std::printf("set-ups: %.6f s of the PEs' recorded set-up work, each PE's before its first task\n", setupWork);
  if (gaps > 0.0) std::printf("controlling thread between stages: %.6f s, replayed serially\n", gaps);
  if (fromRecord && workload.recordedPes == 1)
    std::printf("data messages: a P = 1 record has none to scale, so none are predicted at other P except the results "
                "of cells (record at P > 1 to see a method's traffic)\n");
  std::printf("schedule %s, grain %d; network %s (%s)\n",
              schedule.empty() ? ("as recorded per stage (run: " + workload.schedule + ")").c_str() : schedule.c_str(),
              params.grain, std::string(network.name).c_str(), std::string(network.description).c_str());

  std::vector<par::ScalingPoint> points;
  std::vector<par::RunSummary> summaries;
  std::vector<double> broadcasts;
  std::vector<std::pair<std::string, std::vector<int>>> notes;  // stage notes, and the P they hold for
  std::vector<int> all = pesList;
  if (std::find(all.begin(), all.end(), 1) == all.end()) all.insert(all.begin(), 1);  // T1 for speed-up
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  for (int p : all) {
    par::SimOptions options;
    options.pes = p;
    options.params = params;
    options.network = network;
    const par::Prediction predicted = par::predict(workload, schedule, options);
    points.push_back({p, predicted.record.wallSeconds});
    summaries.push_back(par::summarize(predicted.record));
    broadcasts.push_back(broadcastSeconds(predicted.record, network));
    const std::string text = par::formatStageNotes(predicted.stages);
    auto it = std::find_if(notes.begin(), notes.end(), [&](const auto& n) { return n.first == text; });
    if (it == notes.end()) it = notes.insert(notes.end(), {text, {}});
    it->second.push_back(p);
  }
  for (const auto& [text, ps] : notes) {
    std::string list;
    for (int p : ps) list += (list.empty() ? "" : ",") + std::to_string(p);
    std::printf("\nstages at P = %s:\n%s", list.c_str(), text.c_str());
  }
  std::printf("\n");
  const par::ScalingTable table = par::scalingTable(points);
  std::printf("%6s %14s %10s %8s %10s %11s %12s %14s %12s\n", "P", "makespan s", "speed-up", "effic.", "imbalance",
              "Karp-Flatt", "messages", "bytes", "broadcast s");
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (std::find(pesList.begin(), pesList.end(), all[i]) == pesList.end()) continue;
    const par::ScalingRow& row = table.rows[i];
    const par::StageSummary& total = summaries[i].total;
    char kf[32] = "-";
    if (!std::isnan(row.karpFlatt)) std::snprintf(kf, sizeof kf, "%.4f", row.karpFlatt);
    std::printf("%6d %14.6f %10.3f %8.4f %10.4f %11s %12llu %14llu %12.6f\n", row.pes, row.seconds, row.speedup,
                row.efficiency, total.imbalance, kf,
                (unsigned long long)(total.messages + total.schedulingMessages),
                (unsigned long long)(total.bytes + total.schedulingBytes), broadcasts[i]);
  }
  std::printf("\nbroadcast s: until the last PE has its copy of the replicated data (%s)\n",
              network.sharedMedium ? "on the shared medium PE 0, which holds it, sends the P - 1 copies one after another"
                                   : "MPI's broadcast on a switched network: a binomial tree, or a scatter and an all-gather "
                                     "for long data on 8 PEs or more");
  std::printf("best P: %d (makespan %.6f s); adding PEs beyond P = %d gains less than %.0f%%\n", table.bestPes,
              points[std::find(all.begin(), all.end(), table.bestPes) - all.begin()].seconds, table.saturationPes,
              par::kSaturationTolerance * 100.0);
}

}  // namespace

void addSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "predict makespan, speed-up, efficiency, imbalance and traffic at other P and networks, from a run record "
      "(--metrics JSON) or a cost table (one task cost in seconds per line, optionally 'cost x y'). Each stage of a "
      "record is replayed with the strategy it ran with; --schedule replaces the run's own schedule only, and "
      "owner-pinned stages are scaled by the rules printed per stage");
  cmd->add_option("input", args->input, "run record JSON or cost table")->required()->check(CLI::ExistingFile);
  cmd->add_option("--pes", args->pes, "PE counts to simulate, e.g. 1,2,4,...,1024 (P in [1, 1024])")
      ->capture_default_str();
  cmd->add_option("--network", args->network, "communication model:\n" + par::describeNetworks())
      ->capture_default_str();
  par::addScheduleOptions(*cmd, args->schedule);
  cmd->callback([args, cmd] {
    requireOneRank("simulate");
    args->scheduleGiven = cmd->count("--schedule") > 0;
    runSimulate(*args);
  });
}

}  // namespace pr::cli
