// Tests of `parrender sweep` (tools/cmd_sweep.cpp): the error figures against hand-computed
// values, a small sweep run as a user would (rows for both integrators in the table, the CSV
// and the JSON, the reference stored and then reused), and its input errors.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/util/error.h"
#include "test_support.h"
#include "tools/sweep/image_error.h"

using pr::test::cornell;
using pr::test::join;
using pr::test::runParrender;

namespace {
}  // namespace

TEST_CASE("Sweep: RMSE, relative MSE, maximum error and masked RMSE of a known difference") {
  pr::image::Image reference(2, 1, glm::vec3(1.0f));
  pr::image::Image image = reference;
  image.pixels[0] = glm::vec3(1.0f, 1.0f, 4.0f);  // one channel off by 3
  const pr::cli::ImageError e = pr::cli::imageError(image, reference, {true, false});
  CHECK(e.rmse == doctest::Approx(std::sqrt(9.0 / 6.0)));
  CHECK(e.relativeMse == doctest::Approx(9.0 / 1.01 / 6.0));
  CHECK(e.maxError == doctest::Approx(3.0));
  CHECK(e.maskedPixels == 1);
  CHECK(e.maskedRmse == doctest::Approx(std::sqrt(9.0 / 3.0)));
  const pr::image::Image diff = pr::cli::differenceImage(image, reference);
  CHECK(diff.pixels[0].z == doctest::Approx(24.0f));
  CHECK(diff.pixels[1] == glm::vec3(0.0f));
  CHECK_THROWS_AS(pr::cli::imageError(pr::image::Image(3, 1), reference), pr::InputError);
}

TEST_CASE("Sweep: a small sweep prints both curves, writes CSV and JSON, and reuses its reference") {
  const std::filesystem::path dir = pr::test::scratchDir("sweep");
  const std::string common = join({"sweep ", cornell(), " --width 16 --height 12 --threads 2 --vary photons --values 2000,4000",
                                   " --caustic-photons 1000 --gather 16 --spp 1 --path-spp 1,4 --reference-spp 16",
                                   " --reference-dir \"", (dir / "refs").string(), "\""});
  const auto first = runParrender(join({common, " --csv \"", (dir / "s.csv").string(), "\" --json \"", (dir / "s.json").string(),
                                        "\" --images \"", (dir / "img").string(), "\""}));
  INFO(first.output);
  REQUIRE(first.exitStatus == 0);
  CHECK(first.output.find("reference: rendering") != std::string::npos);
  CHECK(first.output.find("CPU time to reach RMSE") != std::string::npos);
  std::ifstream csv(dir / "s.csv");
  std::string header, line;
  std::getline(csv, header);
  CHECK(header == "integrator,setting,value,cpu_seconds,wall_seconds,rmse,relative_mse,max_error,caustic_rmse");
  int photon = 0, path = 0;
  while (std::getline(csv, line)) {
    photon += line.rfind("photonmap,photons,", 0) == 0;
    path += line.rfind("path,spp,", 0) == 0;
  }
  CHECK(photon == 2);
  CHECK(path == 2);
  std::ifstream in(dir / "s.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["rows"].size() == 4);
  CHECK(j["reference"]["cached"] == false);
  CHECK(j["rows"][0]["rmse"].get<double>() > 0.0);
  CHECK(std::filesystem::exists(dir / "img" / "reference.png"));
  CHECK(std::filesystem::exists(dir / "img" / "photonmap_photons_2000_diff8.png"));
  const auto second = runParrender(common);
  INFO(second.output);
  CHECK(second.exitStatus == 0);
  CHECK(second.output.find("reference: cached") != std::string::npos);
}

TEST_CASE("Sweep: the cache's accuracy and the precomputed-irradiance stride are settings it varies, stride 0 included") {
  const std::filesystem::path dir = pr::test::scratchDir("sweep_cache");
  const std::string common = join({"sweep ", cornell(), " --width 12 --height 12 --threads 2 --integrator photonmap --photons 3000",
                                   " --caustic-photons 1000 --gather 16 --spp 1 --reference-spp 8 --no-cache"});
  const auto stride = runParrender(join({common, " --vary irradiance-stride --values 0,8 --csv \"", (dir / "s.csv").string(), "\""}));
  INFO(stride.output);
  REQUIRE(stride.exitStatus == 0);
  std::ifstream csv(dir / "s.csv");
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(csv, line)) rows.push_back(line);
  REQUIRE(rows.size() == 3);
  CHECK(rows[1].rfind("photonmap,irradiance-stride,0,", 0) == 0);
  CHECK(rows[2].rfind("photonmap,irradiance-stride,8,", 0) == 0);
  const auto accuracy = runParrender(join({common, " --vary cache-accuracy --values 0.5,0.2"}));
  INFO(accuracy.output);
  CHECK(accuracy.exitStatus == 0);
  for (const char* bad : {" --vary cache-accuracy --values 0", " --vary cache-accuracy --values 2", " --vary irradiance-stride --values -1",
                          " --vary irradiance-stride --values 1.5"}) {
    const auto r = runParrender(join({common, bad}));
    CAPTURE(bad);
    CHECK(r.exitStatus == 2);
    CHECK(r.output.find("--values") != std::string::npos);
  }
}

TEST_CASE("Sweep: varying a photon-map setting without the photon map is an input error") {
  const auto r = runParrender(join({"sweep ", cornell(), " --integrator path --vary gather"}));
  CHECK(r.exitStatus == 2);
  CHECK(r.output.find("add photonmap to --integrator") != std::string::npos);
  const auto bad = runParrender(join({"sweep ", cornell(), " --vary photons --values 0"}));
  CHECK(bad.exitStatus == 2);
  CHECK(bad.output.find("--values") != std::string::npos);
  const auto raster = runParrender(join({"sweep ", cornell(), " -m sort-middle"}));
  CHECK(raster.exitStatus == 2);
  CHECK(raster.output.find("ray-tracing") != std::string::npos);
}
