// The render plan on the command line: `info` prints it (table and --json), every `render`
// prints it with what the method simulates and the work it skipped (also in the run record as
// Plan/ counters), `--effects` forces effects and the plan says so; a bad --effects exits 2
// naming the valid effects.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "test_support.h"

using pr::test::join;
using pr::test::quoted;
using pr::test::runParrender;

namespace {
std::string bundled(const char* file) { return quoted(pr::test::sourceDir() / "scenes" / file); }
bool contains(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }
}  // namespace

TEST_CASE("Effects: render --effects with an unknown effect exits 2 naming the valid effects") {
  const auto dir = pr::test::scratchDir("effects_bad");
  const auto r = runParrender(join({"render ", bundled("cornell.gltf"), " --effects bogus=on -o ", quoted(dir / "x.png")}));
  INFO(r.output);
  CHECK(r.exitStatus == 2);
  CHECK(contains(r.output, "unknown effect 'bogus'"));
  CHECK(contains(r.output, "direct, shadows, specular, glossy, transmission, caustics, indirect, anisotropy, textures, emission"));
  CHECK_FALSE(std::filesystem::exists(dir / "x.png"));
  const auto v = runParrender(join({"render ", bundled("cornell.gltf"), " --effects caustics=maybe -o ", quoted(dir / "x.png")}));
  CHECK(v.exitStatus == 2);
  CHECK(contains(v.output, "'maybe' is not on or off"));
}

TEST_CASE("Effects: info prints the plan as a table and in --json") {
  const auto table = runParrender("info " + bundled("cornell-diffuse.gltf"));
  INFO(table.output);
  REQUIRE(table.exitStatus == 0);
  CHECK(contains(table.output, "caustics: off - no ideal specular or transmissive surface"));
  CHECK(contains(table.output, "indirect: on - "));
  const auto json = runParrender("info --json " + bundled("cornell.gltf") + " 2>/dev/null");
  REQUIRE(json.exitStatus == 0);
  const nlohmann::json j = nlohmann::json::parse(json.output);
  REQUIRE(j.contains("plan"));
  CHECK(j["plan"].size() == 10);
  CHECK(j["plan"]["caustics"]["on"] == true);
  CHECK(j["plan"]["glossy"]["on"] == false);
  CHECK(j["plan"]["transmission"]["forced"] == false);
  CHECK(contains(j["plan"]["transmission"]["reason"].get<std::string>(), "glass"));
}

TEST_CASE("Effects: render prints the plan, the forced effects and the skipped work, recorded as Plan/ counters") {
  const auto dir = pr::test::scratchDir("effects_render");
  const auto metrics = dir / "run.json";
  const auto r = runParrender(join({"render ", bundled("cornell.gltf"), " -m image-space --threads 2 -o ",
                                    quoted(dir / "c.png"), " --width 16 --height 16 --spp 1 --max-depth 4",
                                    " --effects shadows=off,caustics=off --metrics ", quoted(metrics)}));
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(contains(r.output, "effects:"));
  CHECK(contains(r.output, "shadows: off (forced off; analysis: on)"));
  CHECK(contains(r.output, "transmission: on - "));
  CHECK(contains(r.output, "integrator path simulates the plan's effects;"));
  CHECK(contains(r.output, "skipped work: "));
  CHECK(contains(r.output, "shadow_tests_skipped "));
  std::ifstream in(metrics);
  std::stringstream text;
  text << in.rdbuf();
  CHECK(contains(text.str(), "Plan/shadow_tests_skipped"));
  CHECK(contains(text.str(), "Plan/caustic_rays_skipped"));
}

TEST_CASE("Effects: a rasterization render prints the plan and the effects it simulates") {
  const auto dir = pr::test::scratchDir("effects_raster");
  const auto r = runParrender(join({"render ", bundled("cornell.gltf"), " -m sort-middle -o ", quoted(dir / "c.png"),
                                    " --width 16 --height 16 --effects indirect=off"}));
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(contains(r.output, "indirect: off (forced off"));
  CHECK(contains(r.output, "rasterization simulates direct light"));
  CHECK(contains(r.output, "not simulated: shadows"));
}
