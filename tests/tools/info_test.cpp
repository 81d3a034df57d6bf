// Tests of `parrender info` (tools/cmd_info.cpp), run as a program: statistics of a good
// file as a table and as JSON, exit status 2 with the loader's message for every bad input,
// and CLI errors for a missing argument or an unknown option.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "test_support.h"
#include "tests/common/scene/gltf_writer.h"

namespace {

// Two instances of a one-triangle mesh: 2 triangles, 6 vertices.
std::filesystem::path writeGoodScene(const std::filesystem::path& dir) {
  pr::test::GltfWriter w = pr::test::oneTriangle();
  w.doc["scenes"][0]["nodes"].push_back(w.addNode({{"mesh", 0}, {"translation", {0, 0, 1}}}));
  return w.write(dir, "two_triangles.gltf");
}

}  // namespace

TEST_CASE("Info: the table lists the triangle count of a good file") {
  auto dir = pr::test::scratchDir("info_table");
  auto path = writeGoodScene(dir);
  auto result = pr::test::runParrender("info \"" + path.string() + "\"");
  INFO(result.output);
  CHECK(result.exitStatus == 0);
  CHECK(result.output.find("triangles        2\n") != std::string::npos);
  CHECK(result.output.find("vertices         6\n") != std::string::npos);
  CHECK(result.output.find("objects          2\n") != std::string::npos);
  CHECK(result.output.find("(automatic, frames the bounds)") != std::string::npos);
}

TEST_CASE("Info: --json gives the same statistics under snake_case keys") {
  auto dir = pr::test::scratchDir("info_json");
  auto path = writeGoodScene(dir);
  auto result = pr::test::runParrender("info --json \"" + path.string() + "\" 2>/dev/null");
  INFO(result.output);
  REQUIRE(result.exitStatus == 0);
  auto j = nlohmann::json::parse(result.output);
  CHECK(j["triangles"] == 2);
  CHECK(j["vertices"] == 6);
  CHECK(j["materials"]["total"] == 1);
  CHECK(j["materials"]["diffuse"] == 1);
  CHECK(j["lights"]["area_triangles"] == 0);
  CHECK(j["bounds"]["max"][2] == 1.0);
  CHECK(j["extensions_used"].empty());
  CHECK(j["memory_bytes"].get<size_t>() > 0);
}

TEST_CASE("Info: a shared model's triangle count and extensions") {
  if (!pr::test::haveSharedScenes()) return;
  auto path = pr::test::sharedScenes() / "TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb";
  auto result = pr::test::runParrender("info --json \"" + path.string() + "\" 2>/dev/null");
  REQUIRE(result.exitStatus == 0);
  auto j = nlohmann::json::parse(result.output);
  CHECK(j["triangles"] == 77792);
  // In the file's own order.
  CHECK(j["extensions_used"] == nlohmann::json::array({"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"}));
  CHECK(j["materials"]["glass"].get<int>() > 0);
  auto table = pr::test::runParrender("info \"" + path.string() + "\" 2>/dev/null");
  CHECK(table.output.find("triangles        77792\n") != std::string::npos);
}

TEST_CASE("Info: --camera selects by name and rejects an unknown one with exit 2") {
  if (!pr::test::haveSharedScenes()) return;
  auto path = (pr::test::sharedScenes() / "Cameras/glTF/Cameras.gltf").string();
  auto byIndex = pr::test::runParrender("info --json --camera 1 \"" + path + "\" 2>/dev/null");
  REQUIRE(byIndex.exitStatus == 0);
  CHECK(nlohmann::json::parse(byIndex.output)["camera"]["projection"] == "orthographic");
  auto bad = pr::test::runParrender("info --camera nosuch \"" + path + "\"");
  CHECK(bad.exitStatus == 2);
  CHECK(bad.output.find("\"nosuch\"") != std::string::npos);
}

TEST_CASE("Info: every bad input exits 2 with the loader's message") {
  auto dir = pr::test::scratchDir("info_bad_inputs");
  for (const auto& bad : pr::test::writeBadInputs(dir)) {
    SUBCASE(bad.name.c_str()) {
      const std::string limit = bad.maxMemory ? " --max-memory " + std::to_string(bad.maxMemory) : "";
      auto result = pr::test::runParrender("info \"" + bad.path.string() + "\"" + limit);
      INFO(result.output);
      CHECK(result.exitStatus == 2);
      CHECK(result.output.find("parrender: error: " + bad.path.string()) != std::string::npos);
      CHECK(result.output.find(bad.expected) != std::string::npos);
    }
  }
}

TEST_CASE("Info: a missing argument or an unknown option is a CLI error (exit 2)") {
  auto missing = pr::test::runParrender("info");
  CHECK(missing.exitStatus == 2);
  CHECK(missing.output.find("scene") != std::string::npos);
  auto dir = pr::test::scratchDir("info_cli");
  auto unknown = pr::test::runParrender("info --frobnicate \"" + writeGoodScene(dir).string() + "\"");
  CHECK(unknown.exitStatus == 2);
  auto help = pr::test::runParrender("info --help");
  CHECK(help.exitStatus == 0);
  CHECK(help.output.find("--json") != std::string::npos);
  CHECK(help.output.find("--camera") != std::string::npos);
}
