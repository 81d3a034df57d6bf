// Tests of `parrender compare` (tools/cmd_compare.cpp, tools/compare/): the bit-for-bit image
// check, a small comparison run as a user would (every valid combination in the table, the
// invalid ones skipped with their reasons, the CSV and JSON rows and their figures), and its
// input errors.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "test_support.h"
#include "tools/sweep/image_error.h"

using pr::test::cornell;
using pr::test::join;
using pr::test::runParrender;

namespace {
}  // namespace

TEST_CASE("Compare: images agree only when every float of every pixel does") {
  pr::image::Image a(3, 2, glm::vec3(0.5f));
  pr::image::Image b = a;
  CHECK(pr::cli::bitDifference(a, b).empty());
  b.pixels[4].y = std::nextafter(0.5f, 1.0f);  // one ulp
  CHECK(pr::cli::bitDifference(a, b).rfind("1 pixels differ", 0) == 0);
  b.pixels[0] = glm::vec3(-0.0f);
  a.pixels[0] = glm::vec3(0.0f);  // equal as numbers, not as bits
  CHECK(pr::cli::bitDifference(a, b).rfind("2 pixels differ", 0) == 0);
  CHECK(pr::cli::bitDifference(a, pr::image::Image(2, 3)) == "a different size");
}

TEST_CASE("Compare: every valid combination is a row, the invalid ones are skipped with their reason") {
  const std::filesystem::path dir = pr::test::scratchDir("compare");
  const auto r = runParrender(join({"compare ", cornell(), " --width 24 --height 16 --spp 1 --max-depth 2",
                                    " --methods sequential,image-space,object-space,sequential-raster,sort-middle,sort-last --threads 1,2,3",
                                    " --compositors direct-send,binary-swap --repeat 2 --reference-spp 4",
                                    " --reference-dir \"", (dir / "refs").string(), "\" --csv \"", (dir / "c.csv").string(),
                                    "\" --json \"", (dir / "c.json").string(), "\" --images \"", (dir / "img").string(), "\""}));
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(r.output.find("skipped sequential demand path P=2: sequential is the one-PE reference") != std::string::npos);
  CHECK(r.output.find("skipped sequential-raster demand P=3: sequential-raster is the one-PE reference") != std::string::npos);
  CHECK(r.output.find("skipped sort-last demand binary-swap P=3: binary-swap needs P a power of two") != std::string::npos);
  CHECK(r.output.find("--spp is a ray-tracing option") != std::string::npos);
  CHECK(r.output.find("every render is bit-identical") != std::string::npos);
  CHECK(r.output.find("[") != std::string::npos);  // progress lines

  std::ifstream in(dir / "c.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  // sequential 1 + image-space 3 + object-space 3 + sequential-raster 1 + sort-middle 3 + sort-last 3
  // + 2 (binary-swap at P = 1, 2)
  REQUIRE(j["rows"].size() == 16);
  CHECK(j["mismatches"] == 0);
  int binarySwap = 0;
  for (const nlohmann::json& row : j["rows"]) {
    CAPTURE(row.dump());
    CHECK(row["wallSeconds"].size() == 2);
    CHECK(row["imageAgrees"] == true);
    CHECK(row["rmse"].get<double>() > 0.0);
    binarySwap += row["compositor"] == "binary-swap";
    const int p = row["pes"];
    if (p == 1) CHECK(row["speedup"].get<double>() == doctest::Approx(1.0));
    else CHECK(row["efficiency"].get<double>() == doctest::Approx(row["speedup"].get<double>() / p));
    // The partitioned tracer's rays travel between PEs; the replicated-scene methods send none.
    if (row["method"] == "object-space" && p > 1) CHECK(row["byKind"]["rays"]["messages"].get<int>() > 0);
    if (row["method"] == "image-space") CHECK_FALSE(row["byKind"].contains("rays"));
    // Each family's Ts is its one-PE reference, the program with no parallel method.
    if (row["family"] == "ray-tracing") CHECK(row["serialReference"] == "sequential demand path P=1");
    else CHECK(row["serialReference"] == "sequential-raster demand P=1");
  }
  CHECK(binarySwap == 2);
  // One family's image check: the rasterizers all match the first rasterizer, so their RMSE is one number.
  CHECK(j["rows"][7]["rmse"] == j["rows"][15]["rmse"]);
  CHECK(j["rows"][7]["method"] == "sequential-raster");

  std::ifstream csv(dir / "c.csv");
  std::string header, line;
  std::getline(csv, header);
  CHECK(header.rfind("method,family,schedule,integrator,compositor,pes,repeats,wall_seconds", 0) == 0);
  CHECK(header.find("rays_messages,rays_bytes") != std::string::npos);
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  CHECK(lines == 16);
  CHECK(std::filesystem::exists(dir / "img" / "reference.png"));
  CHECK(std::filesystem::exists(dir / "img" / "object-space_demand_path_P-2_diff8.png"));
}

TEST_CASE("Compare: bad lists and options of an integrator not compared are input errors") {
  const auto method = runParrender(join({"compare ", cornell(), " --methods image-space,warp-drive"}));
  CHECK(method.exitStatus == 2);
  CHECK(method.output.find("warp-drive") != std::string::npos);
  const auto threads = runParrender(join({"compare ", cornell(), " --threads 1,0"}));
  CHECK(threads.exitStatus == 2);
  const auto photons = runParrender(join({"compare ", cornell(), " --methods image-space --photons 1000 --no-reference"}));
  CHECK(photons.exitStatus == 2);
  CHECK(photons.output.find("add it to --integrators") != std::string::npos);
  const auto help = runParrender("compare --help");
  CHECK(help.exitStatus == 0);
  CHECK(help.output.find("--integrators") != std::string::npos);
  CHECK(help.output.find("--schedules") != std::string::npos);
}
