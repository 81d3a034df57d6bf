// `parrender render --farm` under mpirun (--enable-recovery, loopback, --oversubscribe, every
// command under `timeout`): the farm's image equals the single-process image at 2, 3, 4 and 8
// ranks, with the path tracer and the photon map; a server killed (SIGKILL) or stopped (SIGSTOP,
// continued after the master declared it lost) while it holds a job leaves the image complete
// and identical, the run exits 0 and the record names the lost server, the jobs handed on and
// the late result discarded; bad use is refused with one message; compare and report measure
// the farm beside the SPMD runs and show its servers. The protocol's guarantees
// in one process: tests/common/parallel/farm_test.cpp.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "common/image/image_io.h"
#include "common/parallel/run_record.h"
#include "mpirun_support.h"

using pr::test::cornell;
using pr::test::CommandResult;
using pr::test::join;
using pr::test::occurrences;
using pr::test::quoted;

namespace {


CommandResult farmRun(int ranks, const std::string& args, const std::string& env = "", int limit = 180) {
  return pr::test::mpirun(ranks, "--enable-recovery " + quoted(PARRENDER_EXE), args, limit, env);
}

// What --farm-status wrote ("" when there is no such file): under mpirun --enable-recovery the
// run's exit status reaches the user only that way.
std::string statusIn(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string status;
  std::getline(in, status);
  return status;
}

// The single-process reference image of `args`, written into dir.
pr::image::Image reference(const std::filesystem::path& dir, const std::string& args) {
  const CommandResult one = pr::test::runParrender(join({args, " --quiet -o ", quoted(dir / "reference.exr")}));
  INFO(one.output);
  REQUIRE(one.exitStatus == 0);
  return pr::image::readImage(dir / "reference.exr");
}

// The farm's record: every job counted once, on a server.
void checkEveryJobOnce(const pr::par::RunRecord& record, int servers) {
  REQUIRE(record.farm.has_value());
  const pr::par::FarmRecord& farm = *record.farm;
  CHECK(int(farm.servers.size()) == servers);
  std::size_t counted = 0;
  for (const pr::par::FarmServerRecord& s : farm.servers) counted += s.jobs.size();
  CHECK(counted == farm.jobs.size());
  for (const pr::par::FarmJobRecord& j : farm.jobs) CHECK(j.server >= 1);
}

}  // namespace

TEST_CASE("render --farm: the image equals the single-process image at 2, 3, 4 and 8 ranks") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_equal");
  const std::string common = join({"render ", cornell(), " --width 64 --height 48 --spp 2"});
  const pr::image::Image expected = reference(dir, common);
  for (int ranks : {2, 3, 4, 8}) {
    CAPTURE(ranks);
    const std::filesystem::path out = dir / ("farm" + std::to_string(ranks) + ".exr");
    const std::filesystem::path record = dir / ("farm" + std::to_string(ranks) + ".json");
    // Jobs of 16x8 so that even 7 servers share them; 2 PEs per server at 3 ranks.
    const CommandResult r = farmRun(ranks, join({common, " --farm --farm-job 16x8 --threads ", ranks == 3 ? "2" : "1",
                                                 " -o ", quoted(out), " --metrics ", quoted(record)}));
    INFO(r.output);
    REQUIRE(r.exitStatus == 0);
    CHECK(occurrences(r.output, "as a farm: a master and " + std::to_string(ranks - 1) + " servers") == 1);
    CHECK(pr::image::readImage(out).pixels == expected.pixels);
    checkEveryJobOnce(pr::par::readRunRecord(record), ranks - 1);
  }
}

TEST_CASE("render --farm: the photon map's pre-passes on every server give the single-process image") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_photonmap");
  const std::string common =
      join({"render ", cornell(), " --width 48 --height 36 --integrator photonmap --spp 2 --photons 4000"});
  const pr::image::Image expected = reference(dir, common);
  const CommandResult r = farmRun(3, join({common, " --farm --farm-job 16x12 -o ", quoted(dir / "farm.exr")}));
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(pr::image::readImage(dir / "farm.exr").pixels == expected.pixels);
}

TEST_CASE("render --farm: pre-passes shared among the servers give the single-process image, their traffic counted") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_shared");
  const std::string common =
      join({"render ", cornell(), " --width 48 --height 36 --integrator photonmap --spp 2 --photons 4000"});
  const pr::image::Image expected = reference(dir, common);
  for (const char* prepass : {"replicated", "shared"}) {
    CAPTURE(prepass);
    const std::filesystem::path out = dir / (std::string(prepass) + ".exr"), record = dir / (std::string(prepass) + ".json");
    const CommandResult r = farmRun(4, join({common, " --farm --farm-job 16x12 --farm-prepass ", prepass, " -o ", quoted(out),
                                             " --metrics ", quoted(record)}));
    INFO(r.output);
    REQUIRE(r.exitStatus == 0);
    CHECK(pr::image::readImage(out).pixels == expected.pixels);
    const pr::par::RunRecord run = pr::par::readRunRecord(record);
    REQUIRE(run.farm.has_value());
    CHECK(run.farm->prepass == prepass);
    for (const pr::par::FarmServerRecord& s : run.farm->servers) {
      // Shared: every server sends its share of the photons and records to the others.
      if (std::string(prepass) == "shared")
        CHECK(s.prepareBytes > 0);
      else
        CHECK(s.prepareBytes == 0);
    }
  }
}

TEST_CASE("render --farm: a server killed before its pre-passes are done: replicated goes on, shared fails at once") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_prepass_loss");
  const std::string common =
      join({"render ", cornell(), " --width 48 --height 36 --integrator photonmap --spp 2 --photons 4000 --farm --farm-deadline 2"});
  const pr::image::Image expected = reference(dir, join({"render ", cornell(), " --width 48 --height 36 --integrator photonmap --spp 2 --photons 4000"}));
  // Server rank 2 kills itself as it starts its pre-passes.
  const CommandResult replicated = farmRun(3, join({common, " -o ", quoted(dir / "replicated.exr"), " --farm-status ", quoted(dir / "status")}),
                                           "PARRENDER_FARM_FAULT=2:-1:9", 60);
  INFO(replicated.output);
  CHECK(statusIn(dir / "status") == "0");
  CHECK(replicated.output.find("server rank 2 declared lost") != std::string::npos);
  CHECK(pr::image::readImage(dir / "replicated.exr").pixels == expected.pixels);
  std::filesystem::remove(dir / "status");
  const CommandResult shared = farmRun(3, join({common, " --farm-prepass shared -o ", quoted(dir / "shared.exr"), " --farm-status ",
                                                quoted(dir / "status")}),
                                       "PARRENDER_FARM_FAULT=2:-1:9", 60);
  INFO(shared.output);
  CHECK(shared.exitStatus != 124);  // ended by the master within the deadline, not by timeout
  CHECK(occurrences(shared.output, "farm server rank 2 was lost before its shared pre-passes were done") == 1);
  CHECK(statusIn(dir / "status") == "1");
}

// The render of the loss tests: 100 jobs of 16x12, about 0.05 s each on one core of the 2-core
// machine, 5 s of work, so that the master is still at work when a server stopped early and
// declared lost after the deadline wakes up. Working servers say they are alive, so a loaded
// machine that slows the jobs down loses no server (and only lengthens the run).
const std::string kLossDeadline = "2";
const std::string kLossArgs = " --width 160 --height 120 --spp 256 --farm-job 16x12 --farm-deadline " + kLossDeadline;

TEST_CASE("render --farm: a server killed while it holds a job loses no job, and the run exits 0") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_kill");
  const std::string common = join({"render ", cornell(), kLossArgs});
  const pr::image::Image expected = reference(dir, common);
  // Server rank 2 kills itself (signal 9) as it starts the job after its second result.
  const CommandResult r = farmRun(3, join({common, " --farm --progress --farm-refresh 0.2 -o ", quoted(dir / "farm.exr"),
                                            " --metrics ", quoted(dir / "farm.json"), " --farm-status ", quoted(dir / "status")}),
                                  "PARRENDER_FARM_FAULT=2:2:9");
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(statusIn(dir / "status") == "0");
  CHECK(r.output.find("server rank 2 declared lost") != std::string::npos);
  CHECK(r.output.find("1 server(s) working, 0 preparing, lost: 2") != std::string::npos);  // a --progress line
  CHECK(pr::image::readImage(dir / "farm.exr").pixels == expected.pixels);
  const pr::par::RunRecord record = pr::par::readRunRecord(dir / "farm.json");
  checkEveryJobOnce(record, 2);
  const pr::par::FarmServerRecord& killed = record.farm->servers[1];
  REQUIRE(killed.lost());
  CHECK(killed.jobs.size() == 2);
  CHECK_FALSE(killed.handedOn.empty());
  // Noticed at the deadline after its last message (not before it, and soon after).
  const double deadline = std::stod(kLossDeadline);
  CHECK(killed.lostAtSeconds - killed.lastHeardSeconds >= deadline);
  CHECK(killed.lostAtSeconds - killed.lastHeardSeconds < deadline + 1.0);
  for (int j : killed.handedOn) CHECK(record.farm->jobs[std::size_t(j)].server == 1);
}

TEST_CASE("render --farm: a server stopped and continued after it was declared lost has its late result discarded") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_stop");
  const std::string common = join({"render ", cornell(), kLossArgs});
  const pr::image::Image expected = reference(dir, common);
  const std::filesystem::path pid = dir / "server.pid", log = dir / "farm.log";
  // Server rank 2 stops itself (signal 19) as it starts the job after its second result; once
  // the master has declared it lost, the test continues it (SIGCONT) and it finishes that job.
  const std::string farm = pr::test::kMpiEnv + "PARRENDER_FARM_FAULT=2:2:19:" + quoted(pid) +
                           " timeout 180 mpirun --oversubscribe --enable-recovery -np 3 " + quoted(PARRENDER_EXE) + " " + common +
                           " --farm -o " + quoted(dir / "farm.exr") + " --metrics " + quoted(dir / "farm.json") +
                           " --farm-status " + quoted(dir / "status");
  const std::string script = "(" + farm + " > " + quoted(log) + " 2>&1; echo \"exit $?\" >> " + quoted(log) +
                             ") & for i in $(seq 1 600); do grep -q \"declared lost\" " + quoted(log) +
                             " 2>/dev/null && break; sleep 0.1; done; kill -CONT $(cat " + quoted(pid) + "); wait";
  (void)pr::test::runCommand("bash -c '" + script + "'");  // the script has no single quote
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  INFO(output);
  REQUIRE(output.find("exit 0") != std::string::npos);
  CHECK(statusIn(dir / "status") == "0");
  CHECK(pr::image::readImage(dir / "farm.exr").pixels == expected.pixels);
  const pr::par::RunRecord record = pr::par::readRunRecord(dir / "farm.json");
  checkEveryJobOnce(record, 2);
  const pr::par::FarmServerRecord& stopped = record.farm->servers[1];
  REQUIRE(stopped.lost());
  CHECK(stopped.jobs.size() == 2);
  CHECK(stopped.lateResults == 1);
}

TEST_CASE("render --farm: when the master dies the servers end the run within the deadline, the image left whole") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_master");
  // The master kills itself once it has accepted 10 results, after a refresh or two.
  const CommandResult r =
      farmRun(3, join({"render ", cornell(), kLossArgs, " --farm --farm-refresh 0.1 -o ", quoted(dir / "farm.png"),
                       " --farm-status ", quoted(dir / "status")}),
              "PARRENDER_FARM_FAULT=0:10:9", 60);
  INFO(r.output);
  CHECK(r.exitStatus != 124);  // ended by the servers, not by timeout
  CHECK(r.output.find("the farm's master (rank 0) ") != std::string::npos);  // sent nothing, or took no result
  CHECK(r.output.find("; ending every rank") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "status"));  // no status: the run did not complete
  // The image on disk is the last one the master wrote whole (or none), never a partial file.
  if (std::filesystem::exists(dir / "farm.png")) CHECK(pr::image::readImage(dir / "farm.png").width == 160);
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    CHECK(entry.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("render --farm: bad use is refused with one message") {
  const std::filesystem::path dir = pr::test::scratchDir("render_farm_bad");
  const std::string out = " -o " + quoted(dir / "out.png");
  struct Case {
    int ranks;
    std::string args, message;
  };
  const Case cases[] = {
      {1, "--farm", "--farm needs a master and at least one server"},
      {2, "--farm -m object-space", "--farm renders with image-space only"},
      {2, "--farm -m sort-middle", "sort-middle is a rasterizer"},
      {2, "--farm --farm-schedule hot-spots", "orders jobs by cost estimates"},
      {2, "--farm --farm-job 0x24", "--farm-job must be WIDTHxHEIGHT"},
      {2, "--farm --adaptive", "--adaptive splits tiles"},
      {1, "--progress", "--progress applies to --farm"},
  };
  // Under mpirun --enable-recovery, mpirun exits 0 whatever the ranks' status: --farm-status says it.
  const std::filesystem::path status = dir / "status";
  for (const Case& c : cases) {
    CAPTURE(c.args);
    std::filesystem::remove(status);
    const std::string args = join({"render ", cornell(), " --width 32 --height 24 ", c.args, out});
    const CommandResult r = c.ranks == 1 ? pr::test::runParrender(args) : farmRun(c.ranks, args + " --farm-status " + quoted(status), "", 60);
    INFO(r.output);
    if (c.ranks == 1)
      CHECK(r.exitStatus == 2);
    else
      CHECK(statusIn(status) == "2");
    CHECK(occurrences(r.output, c.message) == 1);
  }
  // The same command line in two working directories whose scene.gltf differ: the hash says so.
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  std::filesystem::copy_file(pr::test::sourceDir() / "scenes" / "cornell.gltf", dir / "a" / "scene.gltf");
  std::filesystem::copy_file(pr::test::sourceDir() / "scenes" / "hotspot.gltf", dir / "b" / "scene.gltf");
  const std::string command =
      quoted(PARRENDER_EXE) + " render scene.gltf --width 32 --height 24 --farm -o out.png --farm-status " + quoted(status);
  std::filesystem::remove(status);
  const CommandResult r = pr::test::runCommand(pr::test::kMpiEnv + "timeout 60 mpirun --oversubscribe --enable-recovery -np 1 -wdir " +
                                               quoted(dir / "a") + " " + command + " : -np 1 -wdir " + quoted(dir / "b") + " " + command);
  INFO(r.output);
  CHECK(statusIn(status) == "2");
  CHECK(occurrences(r.output, "rank 1 loaded a different scene from rank 0's") == 1);
}

TEST_CASE("compare --farm: image-space as a farm beside its SPMD runs, bit-identical, every server in the notes and the JSON") {
  const std::filesystem::path dir = pr::test::scratchDir("compare_farm");
  const std::string args = join({"compare ", cornell(), " --methods image-space --integrators path,photonmap --photons 2000 --threads 1,2",
                                 " --width 64 --height 48 --spp 2 --repeat 2 --no-reference --quiet --farm --farm-job 16x12 --json ",
                                 quoted(dir / "c.json")});
  const CommandResult r = farmRun(3, args);
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(occurrences(r.output, "image-space farm: rank 0 the master, the other 2 ranks servers") == 1);
  CHECK(occurrences(r.output, "images: every render is bit-identical to the first of its family and integrator") == 1);
  std::ifstream in(dir / "c.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  int farms = 0;
  for (const nlohmann::json& row : j["rows"]) {
    if (!row.contains("farm")) continue;
    ++farms;
    CAPTURE(row["agreement"]);
    CHECK(row["imageAgrees"] == true);
    CHECK(row["method"] == "image-space");
    CHECK(row["ranks"] == 3);
    const int threads = row["pes"].get<int>() / 2;  // 2 servers
    CHECK((threads == 1 || threads == 2));
    REQUIRE(row["farm"]["servers"].size() == 2);
    std::size_t jobs = 0;
    for (const nlohmann::json& server : row["farm"]["servers"]) {
      CHECK(server["pes"] == threads);
      CHECK(server["cpuSeconds"].get<double>() > 0.0);  // told at its goodbye
      jobs += server["jobs"].size();
    }
    CHECK(jobs == 16);  // 64x48 in jobs of 16x12
    CHECK(row["speedupSerial"].get<double>() > 0.0);
  }
  CHECK(farms == 4);  // 2 integrators x 2 values of --threads
  // Every farm's servers in the notes, the median run's.
  CHECK(occurrences(r.output, "server rank 1 (1 PE): ") == 2);
  CHECK(occurrences(r.output, "server rank 2 (2 PEs): ") == 2);
  // Without a server: one message.
  const CommandResult alone = pr::test::runParrender(join({"compare ", cornell(), " --methods image-space --farm --quiet"}));
  CHECK(alone.exitStatus == 2);
  CHECK(occurrences(alone.output, "--farm needs a master and at least one server") == 1);
}

TEST_CASE("compare --farm: a server lost during a farm ends the comparison with one message, never a hang") {
  const CommandResult r =
      farmRun(3, join({"compare ", cornell(), " --methods image-space --threads 1 --width 64 --height 48 --spp 2 --repeat 1 --no-reference --quiet",
                       " --farm --farm-job 16x12 --farm-deadline ", kLossDeadline}),
              "PARRENDER_FARM_FAULT=2:-1:9", 90);  // killed as it starts its pre-passes: always
  INFO(r.output);
  CHECK(r.exitStatus != 124);
  CHECK(occurrences(r.output, "farm server rank 2 was lost; compare and report measure the farm") == 1);
}

TEST_CASE("report --farm: a section with the farm beside image-space on the same ranks, every server, and the simulator's replay") {
  const std::filesystem::path dir = pr::test::scratchDir("report_farm");
  const CommandResult r = farmRun(
      3, join({"report ", cornell(), " -o ", quoted(dir / "report"), " --methods image-space --schedules demand --width 64 --height 48",
               " --spp 2 --repeat 1 --reference-spp 4 --photon-spp 1 --path-spp 1 --photons 1000 --reference-dir ", quoted(dir / "refs"),
               " --farm --farm-job 16x12"}),
      "", 300);
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  std::ifstream in(dir / "report" / "index.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE(occurrences(html, "<h3>The render farm</h3>") == 1);
  const std::size_t from = html.find("<h3>The render farm</h3>");
  const std::string farm = html.substr(from, html.find("<h3>", from + 1) - from);
  CHECK(occurrences(farm, "image-space farm(demand) demand path P=2 R=3") == 2);  // the farm's table and its servers'
  CHECK(occurrences(farm, "image-space demand path P=3 R=3: ") == 1);             // SPMD on the same ranks beside it
  CHECK(occurrences(farm, "<tr><td>1</td><td>1</td>") == 1);                      // server ranks 1 and 2, one PE each
  CHECK(occurrences(farm, "<tr><td>2</td><td>1</td>") == 1);
  CHECK(occurrences(farm, "<td>2 (measured: jobs ") == 1);  // the replay's residual at 2 servers
  CHECK(occurrences(farm, "<tr><td>16</td>") == 1);         // and out to one server per job, no further
  CHECK(farm.find("<tr><td>32</td>") == std::string::npos);
}
