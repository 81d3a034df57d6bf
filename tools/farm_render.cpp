// See farm_render.h.
#include "tools/farm_render.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <memory>

#include "common/image/image_io.h"
#include "common/parallel/farm/farm.h"
#include "common/parallel/farm/server_group.h"
#include "common/parallel/metrics.h"
#include "common/parallel/process_group.h"
#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"
#include "common/scene/scene_hash.h"
#include "common/util/error.h"
#include "raytrace/partition/tile_trace.h"

namespace pr::cli {

namespace {

constexpr std::string_view kFarmMethod = "image-space";

struct JobSize {
  int w = 0, h = 0;
};

JobSize parseJobSize(const std::string& text) {
  JobSize s;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &s.w, &x, &s.h, &extra) != 3 || (x != 'x' && x != 'X') || s.w < 1 ||
      s.h < 1 || s.w > 16384 || s.h > 16384)
    throw InputError("--farm-job must be WIDTHxHEIGHT in pixels, e.g. 32x24, not '" + text + "'");
  return s;
}

// An area cut into w x h rectangles in row order, each a task at its centre in rectangle
// units: the image into the master's jobs, and a job into a server's tiles.
struct Areas {
  std::vector<rt::PixelRect> rects;
  par::TaskSet tasks;
};

Areas cut(const rt::PixelRect& area, int w, int h) {
  Areas a;
  a.rects = rt::tilesOf(area, w, h);
  const int cols = (area.x1 - area.x0 + w - 1) / w, rows = (area.y1 - area.y0 + h - 1) / h;
  a.tasks = par::TaskSet::grid(cols, rows);
  return a;
}

// The farm runs of this process so far: every rank runs the same ones (compare and report run
// a farm per combination and repeat), so each counts them alike.
int farmRuns = 0;

par::FarmOptions farmOptions(const FarmArgs& farm, int run) {
  par::FarmOptions o;
  o.deadlineSeconds = farm.deadlineSeconds;
  o.jobsAhead = farm.jobsAhead;
  o.refreshSeconds = farm.refreshSeconds;
  o.readySeconds = par::ProcessGroup::get().timeoutSeconds();
  o.sharedPrepass = farm.prepass == "shared";
  o.run = run;
  return o;
}

// What the run record of shared pre-passes booked between ranks (servers): messages and bytes.
par::PrepareTraffic betweenServers(const par::RunRecord& record) {
  par::PrepareTraffic t;
  for (const par::KindTraffic& k : par::summarize(record).total.byKind) {
    t.messages += k.betweenRankMessages;
    t.bytes += k.betweenRankBytes;
  }
  return t;
}

// A server: its own runtime of `threads` PEs, the world BVH and the integrator's pre-passes
// (on that runtime, or shared: on a runtime across the servers, the master not among them),
// then one stage per job over the job's tiles.
void serve(const FarmArgs& farm, const FarmInput& in, const Areas& jobs, std::uint64_t hash, int run) {
  par::ProcessGroup& group = par::ProcessGroup::get();
  par::Runtime runtime(par::RuntimeOptions{in.threads, in.schedule.schedule, in.schedule.params, false, nullptr});
  const RenderRequest request{in.scene, in.camera, in.width, in.height, in.settings, in.plan, runtime, {}};
  std::unique_ptr<rt::PreparedRays> prepared;
  std::unique_ptr<rt::Bvh> bvh;
  par::ServerGroupTransport servers(group.transport());
  std::unique_ptr<par::Runtime> shared;
  const auto prepare = [&] {
    par::Runtime* pre = &runtime;
    if (farm.prepass == "shared") {
      shared = std::make_unique<par::Runtime>(par::RuntimeOptions{servers.ranks() * in.threads, in.schedule.schedule,
                                                                  in.schedule.params, false, &servers});
      pre = shared.get();
    }
    rt::TraceJob job = rayJobFor(request);
    job.options.bvh.alpha = rt::AlphaTest::forScene(in.scene);
    pre->runOncePerRank("build", [&](par::Pe&) { bvh = std::make_unique<rt::Bvh>(in.scene, job.options.bvh); });
    job.options.worldBvh = bvh.get();
    prepared = std::make_unique<rt::PreparedRays>(rt::prepareRays(job, kFarmMethod, *pre));
    return shared ? betweenServers(shared->record()) : par::PrepareTraffic{};
  };
  const auto work = [&](int id) {
    const rt::TraceJob& job = prepared->job;
    const rt::Integrator& integrator = *job.integrator;
    const rt::PixelRect& area = jobs.rects[std::size_t(id)];
    const Areas tiles = cut(area, job.options.tileSizePx, job.options.tileSizePx);
    rt::Film film(area, in.width, in.height, integrator.options().spp);
    runtime.runStage("farm job", tiles.tasks, [&](par::Pe& pe, par::TaskId t) {
      rt::TraceStats stats;
      const rt::Film tile = rt::traceTile(integrator, *job.options.worldBvh, tiles.rects[t], in.width, in.height, pe.id(), stats);
      film.addBlock(tile.block(tiles.rects[t]));
    });
    return par::encodeMessage(film.block(area));
  };
  par::runFarmServer(group.transport(), farmOptions(farm, run), hash, in.threads, prepare, work);
}

// The master's run record: its PEs are the servers (one per rank), its stages the servers'
// pre-passes and the jobs, each job a span on the server whose result counted.
par::RunRecord farmRunRecord(par::FarmRecord farm, const par::TaskSet& tasks, std::size_t jobBytes) {
  par::RunRecord r;
  const int servers = int(farm.servers.size());
  r.pes = servers;
  r.ranks = servers;
  r.schedule = farm.schedule;
  r.wallSeconds = farm.wallSeconds;
  par::StageRecord prepare;
  prepare.name = "servers' pre-passes";
  prepare.schedule = "each server";
  par::StageRecord jobs;
  jobs.name = "farm jobs";
  jobs.schedule = farm.schedule;
  jobs.tasks = tasks.tasks;
  double firstSent = farm.wallSeconds;
  for (const par::FarmJobRecord& j : farm.jobs) firstSent = std::min(firstSent, j.sentSeconds);
  jobs.startSeconds = firstSent;
  jobs.wallSeconds = farm.wallSeconds - firstSent;
  for (const par::FarmServerRecord& s : farm.servers) prepare.wallSeconds = std::max(prepare.wallSeconds, s.prepareSeconds);
  std::uint64_t results = 0, resultBytes = 0;
  for (const par::FarmServerRecord& s : farm.servers) {
    par::PeStageRecord p;
    p.busySeconds = s.prepareSeconds;
    p.idleSeconds = prepare.wallSeconds - s.prepareSeconds;
    p.tasks = 1;
    prepare.pes.push_back(p);
    par::PeStageRecord q;
    q.busySeconds = s.busySeconds;
    q.idleSeconds = std::max(0.0, jobs.wallSeconds - s.busySeconds);
    q.tasks = s.jobs.size();
    for (int id : s.jobs) {
      q.bytesSent += farm.jobs[std::size_t(id)].resultBytes;
      ++q.messagesSent;
    }
    q.messagesReceived = q.tasks;
    q.bytesReceived = q.tasks * jobBytes;
    results += q.messagesSent;
    resultBytes += q.bytesSent;
    jobs.pes.push_back(q);
  }
  jobs.channels.push_back({"farm results", "results", results, resultBytes, results, resultBytes});
  for (const par::FarmJobRecord& j : farm.jobs)
    if (j.server > 0)
      r.timeline.push_back({j.server - 1, 1, par::TaskId(j.job), j.doneSeconds - j.busySeconds, j.doneSeconds, 0u, 0u, 0.0});
  r.stages = {std::move(prepare), std::move(jobs)};
  r.farm = std::move(farm);
  return r;
}

}  // namespace

void addFarmOptions(CLI::App& command, FarmArgs& args, const std::string& what) {
  command.add_flag("--farm", args.enabled, what);
  command.add_option("--farm-job", args.job, "--farm: a job's screen area, WIDTHxHEIGHT pixels")->capture_default_str();
  command.add_option("--farm-schedule", args.schedule,
                     "--farm: the master's order of jobs, a demand-driven schedule (demand, spiral, random, preferred-bias, ...)")
      ->check(CLI::Validator([](std::string& v) { return par::schedules().problem(v); }, "SCHEDULE"))
      ->capture_default_str();
  command.add_option("--farm-deadline", args.deadlineSeconds,
                     "--farm: seconds a server holding jobs or running its pre-passes may send nothing before it is declared lost")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  command.add_option("--farm-prepass", args.prepass,
                     "--farm: each server runs the pre-passes whole (replicated: no traffic, survives any server's loss) or "
                     "its share of them, the results all-gathered among the servers (shared: less work; a server lost before "
                     "they are done fails the run)")
      ->check(CLI::IsMember({"replicated", "shared"}))
      ->capture_default_str();
  command.add_option("--farm-ahead", args.jobsAhead, "--farm: jobs a server holds at once (the next ones wait there while it works)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
}

void addFarmRenderOptions(CLI::App& command, FarmArgs& args) {
  command.add_option("--farm-refresh", args.refreshSeconds, "--farm: seconds between rewrites of the image (and --progress lines)")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  command.add_option("--farm-status", args.statusFile,
                     "--farm: write the run's exit status (0: complete) to this file at the end; under mpirun --enable-recovery, "
                     "Open MPI 4.1's mpirun exits 0 whatever the ranks' status");
  command.add_flag("--progress", args.progress, "--farm: a progress line on stderr at every refresh (jobs done, servers working and lost)");
}

void reportFarmStatus(const FarmArgs& farm) {
  par::ProcessGroup& group = par::ProcessGroup::get();
  if (farm.statusFile.empty() || group.rank() != 0) return;
  group.atVerdict([file = farm.statusFile](int status) {
    std::FILE* f = std::fopen(file.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "parrender: cannot write the run's status to %s\n", file.c_str());
      return;
    }
    std::fprintf(f, "%d\n", status);
    std::fclose(f);
  });
}

void checkFarm(const FarmArgs& farm, const RenderMethod& method, const RenderSettings& settings, int ranks) {
  if (!farm.enabled) {
    if (farm.progress) throw InputError("--progress applies to --farm");
    if (!farm.statusFile.empty()) throw InputError("--farm-status applies to --farm");
    return;
  }
  if (method.name != kFarmMethod)
    throw InputError("--farm renders with image-space only, whose every server holds all a job needs; " + method.name +
                     (method.properties.family == MethodFamily::Raster ? " is a rasterizer"
                                                                        : "'s data is partitioned among PEs and would be lost with a server"));
  if (ranks < 2)
    throw InputError("--farm needs a master and at least one server: launch parrender under mpirun --enable-recovery -np N, "
                     "with N >= 2");
  if (par::scheduleNeedsCostEstimates(farm.schedule))
    throw InputError("--farm-schedule " + farm.schedule + " orders jobs by cost estimates, which the farm's master (which traces nothing) does not have");
  if (settings.ray.adaptive) throw InputError("--adaptive splits tiles by a cost pre-pass, which the farm does not run");
  (void)parseJobSize(farm.job);
}

void warnWithoutRecovery() {
  // Open MPI's mpirun passes --enable-recovery to its ranks as this variable.
  const char* recovery = std::getenv("OMPI_MCA_orte_enable_recovery");
  if (!recovery || std::string_view(recovery) != "1")
    std::fprintf(stderr, "parrender: warning: --farm without mpirun --enable-recovery: a server that dies ends every rank "
                         "(Open MPI's default); launch it as mpirun --enable-recovery ...\n");
}

FarmRender renderOnFarm(const FarmArgs& farm, const FarmInput& in, const std::string& output) {
  par::ProcessGroup& group = par::ProcessGroup::get();
  par::Transport& transport = group.transport();
  transport.tolerateLostRanks();
  const JobSize size = parseJobSize(farm.job);
  const Areas jobs = cut(rt::PixelRect{0, 0, in.width, in.height}, size.w, size.h);
  const std::uint64_t hash = scene::contentHash(in.scene);
  const int run = farmRuns++;
  if (group.rank() != 0) {
    serve(farm, in, jobs, hash, run);
    return {};
  }
  rt::Film film(in.width, in.height, samplesPerPixel(in.settings.ray));
  std::unique_ptr<par::Scheduler> order = par::makeScheduler(farm.schedule);
  int written = 0;
  const auto accept = [&](int, int, std::span<const std::byte> result) {
    film.addBlock(par::decodeMessage<rt::FilmBlock>(result));
  };
  const auto tick = [&](const par::FarmProgress& p) {
    if (!output.empty() && p.jobsDone != written) {
      image::writeImage(output, film.toImage());
      written = p.jobsDone;
    }
    if (!farm.progress) return;
    std::string lost;
    for (int r : p.lostRanks) lost += (lost.empty() ? "" : ", ") + std::to_string(r);
    std::fprintf(stderr, "farm: %d/%d jobs done, %d server(s) working, %d preparing, lost: %s, %.1f s\n", p.jobsDone, p.jobs,
                 p.serversWorking, p.serversPreparing, lost.empty() ? "none" : lost.c_str(), p.seconds);
  };
  // A lost server is marked at once, so that any ending (a failure too) does not wait for it.
  const auto lost = [&group](int rank) { group.markLost(rank); };
  par::FarmRecord record;
  try {
    record = par::runFarmMaster(transport, farmOptions(farm, run), hash, jobs.tasks, *order, in.schedule.params, accept, tick, lost);
  } catch (const par::FarmSharedPrepassLost& e) {
    group.abortRun(1, e.what());
  } catch (const par::FarmServerFailed& e) {
    if (e.status == kExitBadInput) throw InputError(e.what());
    throw;
  }
  record.jobShape = "screen area " + std::to_string(size.w) + "x" + std::to_string(size.h);
  return FarmRender{farmRunRecord(std::move(record), jobs.tasks, par::kFarmJobBytes), film.toImage()};
}

TimedRender timedFarmRender(const FarmArgs& farm, const RenderInput& input, const RenderSettings& settings, int threads,
                            const par::ScheduleOptions& schedule) {
  par::ProcessGroup& group = par::ProcessGroup::get();
  const double cpu0 = processCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  FarmRender done = renderOnFarm(
      farm, FarmInput{input.scene, input.camera, input.plan, input.width, input.height, settings, schedule, threads}, "");
  TimedRender t;
  if (group.rank() != 0) return t;
  t.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.cpuSeconds = processCpuSeconds() - cpu0;
  for (const par::FarmServerRecord& s : done.record.farm->servers) {
    t.cpuSeconds += s.cpuSeconds;
    if (s.lost())
      group.abortRun(1, "farm server rank " + std::to_string(s.rank) +
                            " was lost; compare and report measure the farm and need every rank for the renders after it "
                            "(render --farm is the farm that goes on without a lost server)");
  }
  t.outcome.image = std::move(done.image);
  t.record = std::move(done.record);
  return t;
}

par::FarmPrediction predictFarmRun(const par::RunRecord& record, int servers, const par::NetworkModel& network,
                                   const std::string& schedule, const par::ScheduleParams& params) {
  if (!record.farm || record.stages.size() < 2) throw InputError("a farm's run record has its jobs as its second stage");
  par::TaskSet tasks;
  tasks.tasks = record.stages[1].tasks;
  std::unique_ptr<par::Scheduler> order = par::makeScheduler(schedule);
  return par::predictFarm(*record.farm, tasks, par::kFarmJobBytes, servers, network, *order, params);
}

std::string farmSummary(const par::RunRecord& record) {
  if (!record.farm) return {};
  const par::FarmRecord& f = *record.farm;
  std::string out;
  const auto line = [&out](const char* format, auto... values) {
    char text[512];
    std::snprintf(text, sizeof text, format, values...);
    out += text;
  };
  line("farm: %zu jobs (%s) in the order of %s, %zu servers, pre-passes %s, deadline %.1f s, wall %.3f s\n", f.jobs.size(),
       f.jobShape.c_str(), f.schedule.c_str(), f.servers.size(), f.prepass.c_str(), f.deadlineSeconds, f.wallSeconds);
  int handedOn = 0, late = 0;
  for (const par::FarmServerRecord& s : f.servers) {
    line("  server rank %d (%d PE%s): %zu jobs, pre-passes %.3f s", s.rank, s.pes, s.pes == 1 ? "" : "s", s.jobs.size(),
         s.prepareSeconds);
    if (f.prepass == "shared")
      line(" (shared: %llu messages, %llu bytes between servers)", (unsigned long long)s.prepareMessages,
           (unsigned long long)s.prepareBytes);
    line(", busy %.3f s, idle %.3f s, CPU %.3f s", s.busySeconds, s.idleSeconds, s.cpuSeconds);
    if (s.lost()) line("; lost at %.2f s (last heard %.2f s), %zu job(s) handed on", s.lostAtSeconds, s.lastHeardSeconds, s.handedOn.size());
    if (s.lateResults > 0) line("; %d late result(s) discarded", s.lateResults);
    out += "\n";
    handedOn += int(s.handedOn.size());
    late += s.lateResults;
  }
  std::uint64_t bytes = 0;
  for (const par::FarmJobRecord& j : f.jobs) bytes += j.resultBytes;
  line("results: %zu messages (%llu bytes) to the master; jobs handed on %d, late results discarded %d\n", f.jobs.size(),
       (unsigned long long)bytes, handedOn, late);
  return out;
}

}  // namespace pr::cli
