// The farm's protocol (common/parallel/farm/farm.h) on ranks inside one process
// (in_process_ranks.h): every job's result is accepted exactly once whatever the master's order;
// a server that dies or stops answering while it holds jobs is declared lost after the deadline
// and no later, its jobs are done by the others and its late results are discarded; a server's
// failure, a scene that differs and the loss of every server end the farm on every rank with
// one reason. The same farm under mpirun, killed and stopped for real: tests/tools/render_farm_test.cpp.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "common/parallel/farm/farm.h"
#include "common/parallel/farm/farm_replay.h"
#include "common/parallel/runtime.h"
#include "common/util/error.h"
#include "in_process_ranks.h"

namespace {

using pr::par::Bytes;
using pr::par::FarmRecord;

// How a server behaves: its job's result is the job id; after `afterJobs` results it dies
// (leaves without a word), or is stopped for `stallSeconds` inside its next job (nothing it
// sends leaves it meanwhile, its keep-alives included, as under SIGSTOP) and then goes on;
// `slowSeconds`: every job of it takes that long.
struct ServerPlan {
  int afterJobs = -1;
  bool dies = false;
  double stallSeconds = 0.0;
  double slowSeconds = 0.0;
  std::uint64_t hash = 7;
  bool fails = false;  // its first job throws
};

struct DeathOfServer {};  // not a std::exception: the server leaves without telling anyone

struct FarmRun {
  FarmRecord record;
  std::vector<int> accepted;      // times each job's result was accepted
  bool resultsRight = true;       // every accepted result was its job's
  std::string masterError;
  std::vector<std::string> serverErrors;  // per rank ("" for rank 0 and servers that ended well)
  int ticks = 0;                          // progress reports
  int ticksNamingLost = 0;                // of them, those that name a lost server
  int lastDone = 0;                       // jobs done at the last report
  std::vector<int> lostRanks;             // as the master declared them lost
};

FarmRun runFarm(int ranks, int jobs, const std::string& schedule, const std::vector<ServerPlan>& plans,
                double deadline = 0.3, double jobSeconds = 0.002) {
  pr::test::InProcessNetwork net(ranks);
  FarmRun run;
  run.accepted.assign(std::size_t(jobs), 0);
  run.serverErrors.assign(std::size_t(ranks), "");
  pr::par::FarmOptions options;
  options.deadlineSeconds = deadline;
  options.refreshSeconds = 0.05;
  options.readySeconds = 10.0;
  pr::test::runWithTimeout(
      [&] {
        std::vector<std::thread> threads;
        for (int r = 1; r < ranks; ++r)
          threads.emplace_back([&, r] {
            const ServerPlan plan = plans.empty() ? ServerPlan{} : plans[std::size_t(r - 1)];
            int done = 0;
            try {
              pr::par::runFarmServer(net.rank(r), options, plan.hash, 1, [] { return pr::par::PrepareTraffic{}; }, [&](int job) {
                if (plan.fails) throw std::runtime_error("no memory for job " + std::to_string(job));
                if (done == plan.afterJobs) {
                  if (plan.dies) throw DeathOfServer{};
                  net.hold(r, true);
                  std::this_thread::sleep_for(std::chrono::duration<double>(plan.stallSeconds));
                  net.hold(r, false);
                }
                std::this_thread::sleep_for(std::chrono::duration<double>(plan.slowSeconds > 0 ? plan.slowSeconds : jobSeconds));
                ++done;
                Bytes b(sizeof(int));
                std::memcpy(b.data(), &job, sizeof job);
                return b;
              });
            } catch (const DeathOfServer&) {
            } catch (const std::exception& e) {
              run.serverErrors[std::size_t(r)] = std::string("thrown: ") + e.what();
            }
          });
        try {
          std::unique_ptr<pr::par::Scheduler> order = pr::par::makeScheduler(schedule);
          run.record = pr::par::runFarmMaster(
              net.rank(0), options, 7, pr::par::TaskSet::grid(jobs, 1), *order, pr::par::ScheduleParams{},
              [&](int job, int, std::span<const std::byte> result) {
                int got = -1;
                if (result.size() == sizeof got) std::memcpy(&got, result.data(), sizeof got);
                run.resultsRight = run.resultsRight && got == job;
                ++run.accepted[std::size_t(job)];
              },
              [&](const pr::par::FarmProgress& p) {
                ++run.ticks;
                run.ticksNamingLost += p.lostRanks.empty() ? 0 : 1;
                run.lastDone = p.jobsDone;
              },
              [&](int rank) { run.lostRanks.push_back(rank); });
        } catch (const std::exception& e) {
          run.masterError = e.what();
        }
        for (std::thread& t : threads) t.join();
      },
      60.0, "farm");
  return run;
}

void checkEveryJobOnce(const FarmRun& run) {
  INFO(run.masterError);
  REQUIRE(run.masterError.empty());
  CHECK(run.resultsRight);
  for (std::size_t j = 0; j < run.accepted.size(); ++j) {
    CAPTURE(j);
    CHECK(run.accepted[j] == 1);
    CHECK(run.record.jobs[j].server > 0);
  }
  std::size_t counted = 0;
  for (const pr::par::FarmServerRecord& s : run.record.servers) counted += s.jobs.size();
  CHECK(counted == run.accepted.size());
}

}  // namespace

TEST_CASE("Farm: every job's result is accepted exactly once, in the order of any schedule") {
  for (const char* schedule : {"demand", "spiral", "random", "preferred-bias", "task-manager", "distributed", "balanced"}) {
    CAPTURE(schedule);
    const FarmRun run = runFarm(4, 40, schedule, {});
    checkEveryJobOnce(run);
    for (const pr::par::FarmServerRecord& s : run.record.servers) {
      CHECK_FALSE(s.lost());
      CHECK(s.lateResults == 0);
    }
  }
}

TEST_CASE("Farm: a server that dies holding jobs is declared lost after the deadline, and its jobs are done by the others") {
  const double deadline = 0.3;
  for (const char* schedule : {"demand", "balanced", "preferred-bias"}) {
    CAPTURE(schedule);
    const FarmRun run = runFarm(4, 60, schedule, {{}, {3, true}, {}}, deadline);
    checkEveryJobOnce(run);
    const pr::par::FarmServerRecord& lost = run.record.servers[1];
    REQUIRE(lost.lost());
    CHECK(lost.jobs.size() == 3);
    CHECK_FALSE(lost.handedOn.empty());
    const double noticed = lost.lostAtSeconds - lost.lastHeardSeconds;
    CHECK(noticed >= deadline);
    CHECK(noticed < deadline + 0.2);
    for (int j : lost.handedOn) {
      CHECK(run.record.jobs[std::size_t(j)].server != 2);
      CHECK(run.record.jobs[std::size_t(j)].attempts == 2);
    }
    CHECK_FALSE(run.record.servers[0].lost());
    CHECK_FALSE(run.record.servers[2].lost());
    CHECK(run.lostRanks == std::vector<int>{2});
  }
}

TEST_CASE("Farm: a server whose jobs take longer than the deadline says it is alive and is not lost") {
  // Both servers take 1 s per job against a deadline of 0.4 s: slow, not lost.
  const FarmRun run = runFarm(3, 4, "demand", {{.slowSeconds = 1.0}, {.slowSeconds = 1.0}}, 0.4);
  checkEveryJobOnce(run);
  CHECK(run.lostRanks.empty());
  for (const pr::par::FarmServerRecord& s : run.record.servers) CHECK(s.busySeconds >= 1.0);
}

TEST_CASE("Farm: a server stopped past the deadline that wakes up has its late result discarded") {
  // Server rank 2 stops for 0.6 s in its third job (deadline 0.2 s) while the others take 1.2 s for the rest.
  const FarmRun run = runFarm(3, 120, "demand", {{}, {2, false, 0.6}}, 0.2, 0.02);
  checkEveryJobOnce(run);
  const pr::par::FarmServerRecord& stalled = run.record.servers[1];
  REQUIRE(stalled.lost());
  CHECK(stalled.lateResults >= 1);
  CHECK(stalled.jobs.size() == 2);  // its late result is not among the ones that counted
  CHECK(run.serverErrors[2].empty());  // told to stop, it ended without a failure
  // Progress every refresh (0.05 s of a run of over a second), the lost server named, the last
  // report the whole image.
  CHECK(run.ticks >= 10);
  CHECK(run.ticksNamingLost >= 1);
  CHECK(run.lastDone == 120);
}

TEST_CASE("Farm: a server's failure ends the farm on every rank with its reason") {
  const FarmRun run = runFarm(3, 20, "demand", {{}, {.fails = true}});
  CHECK(run.masterError.find("server rank 2: no memory for job") != std::string::npos);
  CHECK(run.serverErrors[2].find("no memory for job") != std::string::npos);
  CHECK(run.serverErrors[1].find("failure on another rank") != std::string::npos);
}

TEST_CASE("Farm: a server whose scene differs fails the run, naming its rank") {
  const FarmRun run = runFarm(3, 20, "demand", {{}, {.hash = 8}});
  CHECK(run.masterError.find("rank 2 loaded a different scene") != std::string::npos);
  CHECK_FALSE(run.serverErrors[1].empty());
  CHECK_FALSE(run.serverErrors[2].empty());
}

TEST_CASE("Farm: when every server is lost the master says so instead of waiting") {
  const FarmRun run = runFarm(3, 20, "demand", {{1, true}, {1, true}}, 0.2);
  CHECK(run.masterError.find("every farm server was lost") != std::string::npos);
}

TEST_CASE("Farm replay: jobs shared among servers, results one after another into the master's link") {
  // Eight jobs of 1 s each, one held at a time, results of 1.25 MB (0.1 s at 100 Mbit/s).
  pr::par::FarmRecord farm;
  farm.jobsAhead = 1;
  farm.servers.resize(2);
  for (pr::par::FarmServerRecord& s : farm.servers) s.prepareSeconds = 0.5;
  for (int j = 0; j < 8; ++j) farm.jobs.push_back({j, 1, 0.0, 0.0, 1.0, 1, 1250000});
  const pr::par::TaskSet tasks = pr::par::TaskSet::grid(8, 1);
  const auto predict = [&](int servers, const pr::par::NetworkModel& network) {
    std::unique_ptr<pr::par::Scheduler> order = pr::par::makeScheduler("demand");
    return pr::par::predictFarm(farm, tasks, pr::par::kFarmJobBytes, servers, network, *order, pr::par::ScheduleParams{});
  };
  const pr::par::NetworkModel free{"free", 0.0, 0.0, ""};
  CHECK(predict(1, free).jobsSeconds == doctest::Approx(8.0));
  CHECK(predict(2, free).jobsSeconds == doctest::Approx(4.0));
  CHECK(predict(8, free).jobsSeconds == doctest::Approx(1.0));
  CHECK(predict(8, free).makespanSeconds == doctest::Approx(1.5));  // the pre-passes first
  CHECK(predict(16, free).jobsSeconds == doctest::Approx(1.0));     // no job to share further
  // 8 servers finish together; their results queue at the master's link: the last arrives
  // 8 x 0.1 s later, plus one latency; the job messages (5 bytes) cost a latency each.
  const pr::par::NetworkModel slow{"slow", 0.001, 12.5e6, ""};
  const pr::par::FarmPrediction p = predict(8, slow);
  CHECK(p.masterLinkSeconds == doctest::Approx(0.8));
  CHECK(p.jobsSeconds == doctest::Approx(0.001 + 5 / 12.5e6 + 1.0 + 0.8 + 0.001));
  CHECK_THROWS_AS(predict(0, free), pr::InputError);
}
