// Tests of scene statistics (common/scene/scene_stats.cpp) and Scene::memoryBytes.
#include <doctest/doctest.h>

#include "common/scene/gltf_loader.h"
#include "common/scene/scene_stats.h"
#include "common/util/log.h"
#include "test_support.h"
#include "tests/common/scene/gltf_writer.h"

TEST_CASE("SceneStats: counts what the renderers receive") {
  auto dir = pr::test::scratchDir("scene_stats");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  // Two materials, only the emissive one used; two instances of the triangle mesh.
  w.doc["materials"] = {{{"name", "unused"}}, {{"emissiveFactor", {1, 1, 1}}}};
  w.doc["meshes"][0]["primitives"][0]["material"] = 1;
  w.doc["scenes"][0]["nodes"].push_back(w.addNode({{"mesh", 0}, {"translation", {0, 0, 2}}}));
  w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}}, {{"type", "spot"}, {"spot", nlohmann::json::object()}}};
  w.doc["scenes"][0]["nodes"].push_back(w.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}));
  w.doc["scenes"][0]["nodes"].push_back(w.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}}));
  pr::setQuiet(true);
  auto scene = pr::scene::loadGltf(w.write(dir, "stats.gltf"));
  pr::setQuiet(false);
  auto s = pr::scene::computeStats(scene);
  CHECK(s.triangles == 2);
  CHECK(s.vertices == 6);
  CHECK(s.objects == 2);
  CHECK(s.materials == 1);
  CHECK(s.materialsByKind[size_t(pr::scene::MaterialKind::Emissive)] == 1);
  CHECK(s.pointLights == 1);
  CHECK(s.spotLights == 1);
  CHECK(s.areaLightTriangles == 2);
  CHECK(s.emissiveArea == doctest::Approx(1.0));
  CHECK(s.bounds.max.z == doctest::Approx(2.0f));
  CHECK(s.extensionsUsed == std::vector<std::string>{"KHR_lights_punctual"});
  // memoryBytes covers at least the vertex and triangle arrays.
  CHECK(s.memoryBytes >= 6 * (sizeof(glm::vec3) * 2 + sizeof(glm::vec2)) + 2 * sizeof(pr::scene::Triangle));
}

TEST_CASE("SceneStats: textures and texels of a textured shared model") {
  if (!pr::test::haveSharedScenes()) return;
  pr::setQuiet(true);
  auto scene = pr::scene::loadGltf(pr::test::sharedScenes() / "BoxTextured/glTF/BoxTextured.gltf");
  pr::setQuiet(false);
  auto s = pr::scene::computeStats(scene);
  CHECK(s.textures == 1);
  REQUIRE(scene.textures.size() == 1);
  CHECK(s.texels == size_t(scene.textures[0].width) * size_t(scene.textures[0].height));
  CHECK(s.texels > 0);
  CHECK(s.memoryBytes >= s.texels * 4);
}
