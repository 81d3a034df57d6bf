// `parrender info` on the bundled scenes (scenes/README.md): the figures a user reads must
// match how the generator builds each scene. Expected counts are derived here from the
// scene's construction, not read back from the loader.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace {

nlohmann::json infoJson(const std::filesystem::path& scene) {
  auto result = pr::test::runParrender("info --json \"" + scene.string() + "\" 2>/dev/null");
  INFO(result.output);
  REQUIRE(result.exitStatus == 0);
  return nlohmann::json::parse(result.output);
}

// A UV sphere of n segments and n/2 rings: 2 triangles per quad, one per pole cell.
constexpr int sphereTriangles(int segments) { return segments * (segments / 2 - 1) * 2; }

}  // namespace

TEST_CASE("Info: the bundled Cornell box has 5 walls, two spheres and a two-triangle light") {
  const int expected = 5 * 2 + 2 * sphereTriangles(64) + 2;  // walls, spheres (--size 64), light quad
  auto j = infoJson(pr::test::sourceDir() / "scenes" / "cornell.gltf");
  CHECK(j["triangles"] == expected);
  CHECK(j["materials"]["glass"] == 1);
  CHECK(j["materials"]["specular"] == 1);
  CHECK(j["materials"]["emissive"] == 1);
  CHECK(j["materials"]["diffuse"] == 3);  // white, red, green
  CHECK(j["lights"]["area_triangles"] == 2);
  CHECK(j["lights"]["point"] == 0);
  CHECK(j["cameras"] == 1);
}

TEST_CASE("Info: the diffuse Cornell box has the same triangles and no glass or mirror") {
  auto j = infoJson(pr::test::sourceDir() / "scenes" / "cornell-diffuse.gltf");
  CHECK(j["triangles"] == 5 * 2 + 2 * sphereTriangles(64) + 2);
  CHECK(j["materials"]["glass"] == 0);
  CHECK(j["materials"]["specular"] == 0);
  CHECK(j["materials"]["emissive"] == 1);
  CHECK(j["lights"]["area_triangles"] == 2);
}

TEST_CASE("Info: the hot-spot scene has its point light, area light and sphere cluster") {
  auto j = infoJson(pr::test::sourceDir() / "scenes" / "hotspot.gltf");
  CHECK(j["triangles"] == 80 * sphereTriangles(48) + 6);  // 80 spheres (--size 48) + room and light
  CHECK(j["lights"]["point"] == 1);
  CHECK(j["lights"]["area_triangles"] == 2);
  CHECK(j["materials"]["glass"] == 1);
  CHECK(j["materials"]["specular"] == 1);
}

TEST_CASE("Info: a generated landscape has 2 n^2 terrain triangles plus the lens and the light") {
  auto dir = pr::test::scratchDir("info_landscape");
  auto info = [&](int n) {
    auto path = dir / ("landscape" + std::to_string(n) + ".glb");
    REQUIRE(pr::test::runParrender("generate landscape --size " + std::to_string(n) + " -o \"" + path.string() + "\"").exitStatus == 0);
    return infoJson(path);
  };
  auto small = info(8), large = info(16);
  // The lens and the spherical light are fixed meshes: only the terrain grows with --size.
  const int fixed = small["triangles"].get<int>() - 2 * 8 * 8;
  CHECK(fixed > 0);
  CHECK(large["triangles"] == 2 * 16 * 16 + fixed);
  for (const auto& j : {small, large}) {
    CHECK(j["materials"]["glass"] == 1);
    CHECK(j["materials"]["emissive"] == 1);
    // The spherical light's triangles are area lights; the lens's are not.
    CHECK(j["lights"]["area_triangles"].get<int>() > 0);
    CHECK(j["lights"]["area_triangles"].get<int>() < fixed);
  }
}
