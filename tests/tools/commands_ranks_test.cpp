// compare, sweep and report under mpirun: their renders run across every rank (P = R x T), the
// one-PE baselines on rank 0 alone while the others wait, and rank 0 alone prints and writes.
// compare checks every image against the first of its family, which is the P = 1 render on
// rank 0 alone (the single-process program: no transport), so one compare per R is the matrix
// of every method x integrator x R x T against the single-process image. Every command is
// bounded by `timeout`.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <tuple>

#include <nlohmann/json.hpp>

#include "mpirun_support.h"

using pr::test::cornell;
using pr::test::CommandResult;
using pr::test::join;
using pr::test::occurrences;
using pr::test::quoted;

namespace {

std::string cornellGlass() { return quoted(pr::test::sourceDir() / "scenes" / "cornell-glass.gltf"); }

nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

// Every method but the one-PE references (sequential, sequential-raster) runs across ranks; with each integrator when it traces rays.
const std::set<std::string> kRayMethods = {"image-space", "image-space-cached", "object-space", "object"};
const std::set<std::string> kRasterMethods = {"sort-first", "sort-middle", "sort-last"};
const std::set<std::string> kIntegrators = {"whitted", "path", "photonmap"};

}  // namespace

// The glass box: an area light, a mirror and glass (caustics for the photon map); small images,
// few photons, so that the renders of each R stay within seconds.
TEST_CASE("CommandsRanks: every method x integrator at R = 1, 2, 3, 4 ranks x T = 1, 2 PEs equals the single-process image") {
  const std::filesystem::path dir = pr::test::scratchDir("commands_ranks_matrix");
  const std::string args = join({"compare ", cornellGlass(),
                                 " --width 24 --height 20 --spp 2 --tile-size 8 --repeat 1 --no-reference --quiet"
                                 " --threads 1,2 --integrators whitted,path,photonmap --compositors direct-send,binary-swap"
                                 " --photons 3000 --caustic-photons 3000 --gather 8"});
  for (int ranks : {1, 2, 3, 4}) {
    CAPTURE(ranks);
    const std::filesystem::path json = dir / join({"r", std::to_string(ranks), ".json"});
    const std::string command = join({args, " --json ", quoted(json)});
    const CommandResult r = ranks == 1 ? pr::test::runParrender(command) : pr::test::mpirun(ranks, quoted(PARRENDER_EXE), command, 180);
    INFO(r.output);
    REQUIRE(r.exitStatus == 0);
    CHECK(occurrences(r.output, "images: every render is bit-identical to the first of its family") == 1);  // rank 0 alone
    const nlohmann::json j = readJson(json);
    CHECK(j["mismatches"] == 0);
    // Which (method, integrator, T) ran across every rank, each agreeing with the P = 1 image;
    // under mpirun the P = 1 rows ran on rank 0 alone (the T1 and Ts of every row), and
    // sequential and sequential-raster nowhere else.
    std::set<std::tuple<std::string, std::string, int>> ran;
    int alone = 0;
    for (const nlohmann::json& row : j["rows"]) {
      CAPTURE(row.dump());
      CHECK(row["imageAgrees"] == true);
      CHECK(row["speedup"].get<double>() > 0.0);
      const int pes = row["pes"], rowRanks = row["ranks"];
      if (ranks > 1 && pes == 1) {
        ++alone;
        CHECK(rowRanks == 1);
        continue;
      }
      CHECK(rowRanks == ranks);
      if (ranks > 1) CHECK(row["method"] != "sequential");
      if (ranks > 1) CHECK(row["method"] != "sequential-raster");
      ran.insert({row["method"], row["integrator"], pes / ranks});
    }
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      for (const std::string& m : kRayMethods)
        for (const std::string& i : kIntegrators) {
          CAPTURE(m);
          CAPTURE(i);
          CHECK(ran.count({m, i, threads}) == 1);
        }
      for (const std::string& m : kRasterMethods) {
        CAPTURE(m);
        CHECK(ran.count({m, "-", threads}) == 1);
      }
    }
    // sequential and the 4 tracers per integrator, sequential-raster and the 3 sort points
    // (sort-last twice)
    if (ranks > 1) CHECK(alone == 5 * 3 + 5);
  }
}

// The sweep's renders run across ranks, so its figures are the single-process run's: the
// same RMSE to the last digit printed, the reference cached by rank 0 and found again.
TEST_CASE("CommandsRanks: sweep across 2 ranks gives the RMSE of the single-process sweep, rank 0 alone printing") {
  const std::filesystem::path dir = pr::test::scratchDir("commands_ranks_sweep");
  const std::string args = join({"sweep ", cornellGlass(), " --width 24 --height 20 --reference-spp 4 --vary spp --values 1,2",
                                 " --path-spp 1,2 --photons 3000 --caustic-photons 3000 --gather 8 --reference-dir ",
                                 quoted(dir / "refs")});
  const CommandResult one = pr::test::runParrender(join({args, " --threads 2 --json ", quoted(dir / "one.json")}));
  INFO(one.output);
  REQUIRE(one.exitStatus == 0);
  const CommandResult ranks = pr::test::mpirun(2, quoted(PARRENDER_EXE), join({args, " --threads 1 --json ", quoted(dir / "ranks.json")}), 120);
  INFO(ranks.output);
  REQUIRE(ranks.exitStatus == 0);
  CHECK(occurrences(ranks.output, "sweep of ") == 1);
  CHECK(ranks.output.find("P 2 (2 ranks x 1 PEs)") != std::string::npos);
  CHECK(ranks.output.find("(cached)") != std::string::npos);  // rank 0 found the first run's reference
  const nlohmann::json a = readJson(dir / "one.json"), b = readJson(dir / "ranks.json");
  REQUIRE(a["rows"].size() == 4);
  REQUIRE(b["rows"].size() == a["rows"].size());
  for (std::size_t i = 0; i < a["rows"].size(); ++i) {
    CAPTURE(i);
    CHECK(b["rows"][i]["rmse"] == a["rows"][i]["rmse"]);
    CHECK(b["rows"][i]["causticRmse"] == a["rows"][i]["causticRmse"]);
  }
}

// The report's renders run across ranks; rank 0 alone prepares, writes and puts the folder in
// place, and a folder it refuses ends every rank with one message and nothing left behind.
TEST_CASE("CommandsRanks: report across 2 ranks writes one report from rank 0, and a refused folder is one message with no hang") {
  const std::filesystem::path dir = pr::test::scratchDir("commands_ranks_report");
  const std::string args = join({"report ", cornell(), " --methods image-space,image-space-cached,sort-last --schedules demand",
                                 " --width 24 --height 20 --repeat 1 --reference-spp 4 --photon-spp 1 --path-spp 1",
                                 " --cache-mb 0,1 --photons 2000 --caustic-photons 1000 --gather 8 --max-pes 8 --reference-dir ",
                                 quoted(dir / "refs")});
  const CommandResult r = pr::test::mpirun(2, quoted(PARRENDER_EXE), join({args, " -o ", quoted(dir / "out")}), 180);
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(occurrences(r.output, "report: ") >= 1);
  CHECK(occurrences(r.output, "index.html") == 1);
  std::ifstream page(dir / "out" / "index.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  CHECK(html.find("P in {1, 2} across 2 ranks launched by mpirun") != std::string::npos);
  CHECK(html.find("Every render matched the first of its family bit for bit") != std::string::npos);
  CHECK(html.find("Every cache size gave the comparison's image bit for bit") != std::string::npos);
  const nlohmann::json c = readJson(dir / "out" / "cornell" / "comparison.json");
  CHECK(c["mismatches"] == 0);
  CHECK(c["rows"].size() == 6);  // three methods at P = 1 (rank 0 alone) and P = 2 (2 ranks)

  // Someone's folder, not a report: refused by rank 0 before any render, every rank ends.
  const std::filesystem::path mine = dir / "mine";
  std::filesystem::create_directories(mine);
  std::ofstream(mine / "notes.txt") << "keep me\n";
  const CommandResult refused = pr::test::mpirun(2, quoted(PARRENDER_EXE), join({args, " -o ", quoted(mine)}), 60);
  INFO(refused.output);
  CHECK(refused.exitStatus == 2);
  CHECK(occurrences(refused.output, "holds files that are not a parrender report") == 1);
  CHECK(std::filesystem::exists(mine / "notes.txt"));
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    CHECK(entry.path().filename().string().rfind(".mine.new-", 0) != 0);  // no half-made report beside it
}
