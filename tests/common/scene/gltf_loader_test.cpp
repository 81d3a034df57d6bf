// Tests of the glTF loader (common/scene/gltf_loader.cpp): the shared sample models against
// the counts of /work/shared/scenes/README.md, and small files written here whose world-space
// results are computed by hand next to each case.
#include <doctest/doctest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "common/util/log.h"
#include "test_support.h"
#include "tests/common/scene/gltf_writer.h"

namespace {

using pr::scene::Scene;

struct SharedModel {
  const char* file;
  size_t triangles;  // "scene" column: every node instance counted
  std::vector<std::string> extensions;
};

// The 20 files of shared/scenes/README.md with their scene triangle counts and extensions.
const std::vector<SharedModel> kSharedModels = {
    {"Box/glTF/Box.gltf", 12, {}},
    {"Box/glTF-Binary/Box.glb", 12, {}},
    {"Box/glTF-Embedded/Box.gltf", 12, {}},
    {"BoxTextured/glTF/BoxTextured.gltf", 12, {}},
    {"BoxTextured/glTF-Embedded/BoxTextured.gltf", 12, {}},
    {"Duck/glTF-Binary/Duck.glb", 4212, {}},
    {"Avocado/glTF/Avocado.gltf", 682, {}},
    {"MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb", 1040409, {}},
    {"BoxInterleaved/glTF/BoxInterleaved.gltf", 12, {}},
    {"SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf", 12, {}},
    {"TriangleWithoutIndices/glTF-Embedded/TriangleWithoutIndices.gltf", 1, {}},
    {"Cameras/glTF/Cameras.gltf", 2, {}},
    {"OrientationTest/glTF-Binary/OrientationTest.glb", 524, {}},
    {"NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb", 7724, {}},
    {"LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", 6000, {"KHR_lights_punctual", "KHR_materials_transmission"}},
    {"TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb", 77792,
     {"KHR_materials_ior", "KHR_materials_transmission", "KHR_materials_volume"}},
    {"AttenuationTest/glTF-Binary/AttenuationTest.glb", 292, {"KHR_materials_transmission", "KHR_materials_volume"}},
    {"EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb", 90, {"KHR_materials_emissive_strength"}},
    {"AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb", 97240, {"KHR_materials_anisotropy"}},
    {"TextureTransformTest/glTF/TextureTransformTest.gltf", 24, {"KHR_texture_transform"}},
};

Scene loadQuiet(const std::filesystem::path& path) {
  pr::setQuiet(true);
  Scene scene = pr::scene::loadGltf(path);
  pr::setQuiet(false);
  return scene;
}

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Geometric normal from the stored winding (counter-clockwise = front).
glm::vec3 windingNormal(const Scene& s, size_t t) {
  const auto& tri = s.triangles[t];
  return glm::normalize(glm::cross(s.positions[tri.v[1]] - s.positions[tri.v[0]],
                                   s.positions[tri.v[2]] - s.positions[tri.v[0]]));
}

void checkNear(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
  INFO("got (" << a.x << ", " << a.y << ", " << a.z << ") expected (" << b.x << ", " << b.y << ", " << b.z << ")");
  CHECK(glm::length(a - b) < eps);
}

// Loads one shared model and checks the README's counts plus the render-ready invariants.
Scene checkSharedModel(const SharedModel& m) {
  INFO(m.file);
  Scene s = loadQuiet(pr::test::sharedScenes() / m.file);
  CHECK(s.triangles.size() == m.triangles);
  CHECK(sorted(s.extensionsUsed) == sorted(m.extensions));
  CHECK(s.normals.size() == s.positions.size());
  CHECK(s.uvs.size() == s.positions.size());
  CHECK(!s.materials.empty());
  size_t objectTriangles = 0;
  for (const auto& o : s.objects) objectTriangles += o.triangleCount;
  CHECK(objectTriangles == s.triangles.size());
  size_t badReferences = 0;
  for (const auto& t : s.triangles) {
    badReferences += t.material >= s.materials.size() || t.v[0] >= s.positions.size() ||
                     t.v[1] >= s.positions.size() || t.v[2] >= s.positions.size();
  }
  CHECK(badReferences == 0);
  return s;
}

// The models are split over several cases so each stays well under a second: the big
// textures of Avocado and LightsPunctualLamp take most of the decoding time.
bool isHeavy(const SharedModel& m) {
  std::string f = m.file;
  return f.rfind("Avocado", 0) == 0 || f.rfind("LightsPunctualLamp", 0) == 0 || f.rfind("MetalRough", 0) == 0;
}

}  // namespace

TEST_CASE("GltfLoader: the light shared models load with the README's triangle counts and extensions") {
  if (!pr::test::haveSharedScenes()) return;
  size_t checked = 0;
  for (const SharedModel& m : kSharedModels) {
    if (isHeavy(m)) continue;
    checkSharedModel(m);
    ++checked;
  }
  CHECK(checked == 17);
}

TEST_CASE("GltfLoader: MetalRoughSpheresNoTextures gives 1,040,409 triangles from shared accessors") {
  if (!pr::test::haveSharedScenes()) return;
  checkSharedModel(kSharedModels[7]);
}

TEST_CASE("GltfLoader: Avocado loads with the README's triangle count") {
  if (!pr::test::haveSharedScenes()) return;
  checkSharedModel(kSharedModels[6]);
}

TEST_CASE("GltfLoader: LightsPunctualLamp loads with the README's triangle count and extensions") {
  if (!pr::test::haveSharedScenes()) return;
  // Five point lights (candela, no range), placed by their nodes.
  Scene lamp = checkSharedModel(kSharedModels[14]);
  CHECK(lamp.lights.size() == 5);
  for (const auto& l : lamp.lights) CHECK((l.type == pr::scene::LightType::Point));
}

TEST_CASE("GltfLoader: Box as .gltf, .glb and embedded .gltf gives the same world geometry") {
  if (!pr::test::haveSharedScenes()) return;
  Scene a = loadQuiet(pr::test::sharedScenes() / "Box/glTF/Box.gltf");
  Scene b = loadQuiet(pr::test::sharedScenes() / "Box/glTF-Binary/Box.glb");
  Scene c = loadQuiet(pr::test::sharedScenes() / "Box/glTF-Embedded/Box.gltf");
  REQUIRE(a.positions.size() == 24);
  CHECK(a.positions == b.positions);
  CHECK(a.positions == c.positions);
  // The root matrix turns Z-up into Y-up; the unit cube stays centred at the origin.
  checkNear(a.bounds.min, glm::vec3(-0.5f));
  checkNear(a.bounds.max, glm::vec3(0.5f));
  // One red factor-only material; Box is a closed cube so every winding normal points outward.
  CHECK(a.materials.front().baseColorFactor.x > 0.7f);
  for (size_t t = 0; t < a.triangles.size(); ++t) {
    glm::vec3 centroid = (a.positions[a.triangles[t].v[0]] + a.positions[a.triangles[t].v[1]] +
                          a.positions[a.triangles[t].v[2]]) / 3.0f;
    CHECK(glm::dot(windingNormal(a, t), centroid) > 0.0f);
  }
  // The authored normals went through the root matrix too: each is an outward face normal.
  for (size_t v = 0; v < a.positions.size(); ++v) {
    CHECK(glm::length(a.normals[v]) == doctest::Approx(1.0f));
    CHECK(glm::dot(a.normals[v], a.positions[v]) == doctest::Approx(0.5f));
  }
}

TEST_CASE("GltfLoader: BoxInterleaved equals Box geometry") {
  if (!pr::test::haveSharedScenes()) return;
  Scene box = loadQuiet(pr::test::sharedScenes() / "Box/glTF/Box.gltf");
  Scene inter = loadQuiet(pr::test::sharedScenes() / "BoxInterleaved/glTF/BoxInterleaved.gltf");
  REQUIRE(inter.positions.size() == box.positions.size());
  REQUIRE(inter.triangles.size() == box.triangles.size());
  for (size_t i = 0; i < box.positions.size(); ++i) {
    checkNear(inter.positions[i], box.positions[i]);
    checkNear(inter.normals[i], box.normals[i]);
  }
  for (size_t t = 0; t < box.triangles.size(); ++t) {
    CHECK(inter.triangles[t].v[0] == box.triangles[t].v[0]);
    CHECK(inter.triangles[t].v[2] == box.triangles[t].v[2]);
  }
}

TEST_CASE("GltfLoader: SimpleSparseAccessor substitutes its three sparse positions") {
  if (!pr::test::haveSharedScenes()) return;
  Scene s = loadQuiet(pr::test::sharedScenes() / "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf");
  // The base grid is 14 vertices at y = 0 (x = 0..6, two rows); sparse indices 8, 10, 12
  // lift (1,2,0), (3,3,0), (5,4,0) (values from the file's sparse bufferView).
  REQUIRE(s.positions.size() == 14);
  checkNear(s.positions[8], glm::vec3(1, 2, 0));
  checkNear(s.positions[10], glm::vec3(3, 3, 0));
  checkNear(s.positions[12], glm::vec3(5, 4, 0));
  checkNear(s.positions[9], glm::vec3(2, 1, 0));  // not substituted
  CHECK(s.bounds.max.y == doctest::Approx(4.0f));
  // No material: every triangle uses the default material, which is last.
  for (const auto& t : s.triangles) CHECK(t.material == s.materials.size() - 1);
}

TEST_CASE("GltfLoader: TRS hierarchy gives hand-computed world positions") {
  auto dir = pr::test::scratchDir("gltf_trs");
  pr::test::GltfWriter w;
  int pos = w.addFloats({1, 0, 0, 0, 1, 0, 0, 0, 1}, "VEC3");
  int mesh = w.addMesh({{"POSITION", pos}});
  // Child: translate (0, 0, 1), scale 2. Parent: translate (10, 0, 0), rotate 90 deg about +Z
  // (quaternion (0, 0, sin 45, cos 45)), scale 3.
  int child = w.addNode({{"mesh", mesh}, {"translation", {0, 0, 1}}, {"scale", {2, 2, 2}}});
  const double h = std::sqrt(0.5);
  int parent = w.addNode({{"children", {child}}, {"translation", {10, 0, 0}}, {"rotation", {0, 0, h, h}},
                          {"scale", {3, 3, 3}}});
  w.setRoots({parent});
  Scene s = loadQuiet(w.write(dir, "trs.gltf"));
  REQUIRE(s.positions.size() == 3);
  // world(p) = T(10,0,0) R_z(90) S(3) [ T(0,0,1) S(2) p ];  R_z(90): (x, y, z) -> (-y, x, z).
  // (1,0,0): child -> (2,0,1); S3 -> (6,0,3); R -> (0,6,3); T -> (10,6,3).
  checkNear(s.positions[0], glm::vec3(10, 6, 3), 1e-4f);
  // (0,1,0): child -> (0,2,1); S3 -> (0,6,3); R -> (-6,0,3); T -> (4,0,3).
  checkNear(s.positions[1], glm::vec3(4, 0, 3), 1e-4f);
  // (0,0,1): child -> (0,0,3); S3 -> (0,0,9); R -> (0,0,9); T -> (10,0,9).
  checkNear(s.positions[2], glm::vec3(10, 0, 9), 1e-4f);
  REQUIRE(s.objects.size() == 1);
  CHECK(s.objects[0].node == child);
}

TEST_CASE("GltfLoader: a node matrix is used as given (column-major)") {
  auto dir = pr::test::scratchDir("gltf_matrix");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  // Translation (1, 2, 3) sits in elements 12..14 of the column-major array.
  w.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1};
  Scene s = loadQuiet(w.write(dir, "matrix.gltf"));
  checkNear(s.positions[1], glm::vec3(2, 2, 3));
}

TEST_CASE("GltfLoader: negative scale keeps facing (winding swapped, normals by inverse transpose)") {
  auto dir = pr::test::scratchDir("gltf_mirror");
  pr::test::GltfWriter w;
  // Triangle in z = 0 wound counter-clockwise seen from +Z, authored normal +Z.
  int pos = w.addFloats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  int nrm = w.addFloats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  int mesh = w.addMesh({{"POSITION", pos}, {"NORMAL", nrm}});
  // Mirror in z through a parent, plus a non-uniform scale on the child: the mirrored front
  // faces -Z, and inverse-transpose keeps the normal perpendicular to the scaled surface.
  int child = w.addNode({{"mesh", mesh}, {"scale", {2, 1, 1}}});
  w.setRoots({w.addNode({{"children", {child}}, {"scale", {1, 1, -1}}})});
  Scene s = loadQuiet(w.write(dir, "mirror.gltf"));
  REQUIRE(s.triangles.size() == 1);
  checkNear(windingNormal(s, 0), glm::vec3(0, 0, -1));
  for (const glm::vec3& n : s.normals) checkNear(n, glm::vec3(0, 0, -1));
}

TEST_CASE("GltfLoader: NegativeScaleTest winding agrees with its authored normals") {
  if (!pr::test::haveSharedScenes()) return;
  Scene s = loadQuiet(pr::test::sharedScenes() / "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb");
  // After mirroring fixes, the winding normal of each non-degenerate triangle must lie on the
  // same side as the average of its (inverse-transposed) vertex normals.
  size_t agree = 0, checked = 0;
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& tri = s.triangles[t];
    glm::vec3 c = glm::cross(s.positions[tri.v[1]] - s.positions[tri.v[0]], s.positions[tri.v[2]] - s.positions[tri.v[0]]);
    if (glm::length(c) < 1e-12f) continue;
    ++checked;
    if (glm::dot(c, s.normals[tri.v[0]] + s.normals[tri.v[1]] + s.normals[tri.v[2]]) > 0.0f) ++agree;
  }
  REQUIRE(checked > 7000);
  CHECK(agree == checked);
}

TEST_CASE("GltfLoader: triangle strips and fans become triangle lists with front-facing winding") {
  auto dir = pr::test::scratchDir("gltf_strip_fan");
  // Four vertices of a unit square in z = 0, in strip order and in fan order.
  pr::test::GltfWriter w;
  int strip = w.addFloats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3");
  int fan = w.addFloats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3");
  int stripMesh = w.addMesh({{"POSITION", strip}}, -1, 5);
  int fanMesh = w.addMesh({{"POSITION", fan}}, -1, 6);
  w.setRoots({w.addNode({{"mesh", stripMesh}}), w.addNode({{"mesh", fanMesh}, {"translation", {0, 0, 1}}})});
  Scene s = loadQuiet(w.write(dir, "strip_fan.gltf"));
  REQUIRE(s.triangles.size() == 4);  // n - 2 each
  // Strip: {0,1,2}, {1,3,2}; fan: {1,2,0}, {2,3,0} (spec 3.7.2.1), offset by the fan's base 4.
  CHECK(s.triangles[0].v[0] == 0);
  CHECK(s.triangles[0].v[1] == 1);
  CHECK(s.triangles[0].v[2] == 2);
  CHECK(s.triangles[1].v[0] == 1);
  CHECK(s.triangles[1].v[1] == 3);
  CHECK(s.triangles[1].v[2] == 2);
  CHECK(s.triangles[2].v[0] == 5);
  CHECK(s.triangles[2].v[1] == 6);
  CHECK(s.triangles[2].v[2] == 4);
  CHECK(s.triangles[3].v[0] == 6);
  CHECK(s.triangles[3].v[1] == 7);
  CHECK(s.triangles[3].v[2] == 4);
  for (size_t t = 0; t < 4; ++t) checkNear(windingNormal(s, t), glm::vec3(0, 0, 1));
  CHECK(s.objects.size() == 2);
}

TEST_CASE("GltfLoader: points and lines are skipped with a warning") {
  auto dir = pr::test::scratchDir("gltf_points");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  int pos = w.addFloats({0, 0, 0, 1, 1, 1}, "VEC3");
  int points = w.addMesh({{"POSITION", pos}}, -1, 0);
  int lines = w.addMesh({{"POSITION", pos}}, -1, 1);
  w.doc["scenes"][0]["nodes"].push_back(w.addNode({{"mesh", points}}));
  w.doc["scenes"][0]["nodes"].push_back(w.addNode({{"mesh", lines}}));
  Scene s = loadQuiet(w.write(dir, "points.gltf"));
  CHECK(s.triangles.size() == 1);
  REQUIRE(s.warnings.size() == 2);
  CHECK(s.warnings[0].find("POINTS skipped") != std::string::npos);
  CHECK(s.warnings[1].find("LINES skipped") != std::string::npos);
}

TEST_CASE("GltfLoader: missing normals are generated, area-weighted") {
  auto dir = pr::test::scratchDir("gltf_normals");
  pr::test::GltfWriter w;
  // Two triangles sharing vertex 0 at the origin: a large one in z = 0 (area 8, normal +Z)
  // and a small one in x = 0 (area 0.5, normal +X). Vertex 0's normal is (0.5, 0, 8)
  // normalised; the other vertices keep their own face normal.
  int pos = w.addFloats({0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 1, 0, 0, 0, 1}, "VEC3");
  int idx = w.addIndices({0, 1, 2, 0, 3, 4});
  w.setRoots({w.addNode({{"mesh", w.addMesh({{"POSITION", pos}}, idx)}})});
  Scene s = loadQuiet(w.write(dir, "normals.gltf"));
  REQUIRE(s.normals.size() == 5);
  checkNear(s.normals[0], glm::normalize(glm::vec3(0.5f, 0, 8)));
  checkNear(s.normals[1], glm::vec3(0, 0, 1));
  checkNear(s.normals[4], glm::vec3(1, 0, 0));
}

TEST_CASE("GltfLoader: normalized integer attributes and vertex colours are decoded") {
  auto dir = pr::test::scratchDir("gltf_normalized");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  // TEXCOORD_0 as normalized UNSIGNED_SHORT, COLOR_0 as normalized UNSIGNED_BYTE VEC3.
  std::vector<uint16_t> uv = {0, 0, 65535, 0, 0, 32768};
  int uvView = w.addView(uv.data(), uv.size() * 2);
  w.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = w.addAccessor(uvView, 5123, 3, "VEC2", 0, true);
  std::vector<uint8_t> color = {255, 0, 0, 0, 255, 0, 0, 0, 51, 0};  // vec3 rows, padded at the end
  int colorView = w.addView(color.data(), color.size());
  w.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = w.addAccessor(colorView, 5121, 3, "VEC3", 0, true);
  Scene s = loadQuiet(w.write(dir, "normalized.gltf"));
  CHECK(s.uvs[1].x == doctest::Approx(1.0f));
  CHECK(s.uvs[2].y == doctest::Approx(32768.0f / 65535.0f));
  REQUIRE(s.colors.size() == 3);
  CHECK(s.colors[0] == glm::vec4(1, 0, 0, 1));
  CHECK(s.colors[2].z == doctest::Approx(0.2f));
}

TEST_CASE("GltfLoader: lights and cameras are placed by their nodes") {
  auto dir = pr::test::scratchDir("gltf_lights");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "spot"}, {"intensity", 100}, {"color", {1, 0.5, 0.25}}, {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}},
      {{"type", "directional"}, {"intensity", 3}}};
  // Spot at (0, 5, 0) rotated -90 deg about X: its -Z axis turns to -Y (pointing down).
  const double h = std::sqrt(0.5);
  w.addNode({{"translation", {0, 5, 0}}, {"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  w.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  w.doc["cameras"] = {{{"type", "perspective"}, {"name", "persp"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}};
  w.addNode({{"camera", 0}, {"translation", {0, 0, 10}}, {"scale", {0.01, 0.01, 0.01}}});
  w.doc["scenes"][0]["nodes"] = {0, 1, 2, 3};
  Scene s = loadQuiet(w.write(dir, "lights.gltf"));
  REQUIRE(s.lights.size() == 2);
  CHECK((s.lights[0].type == pr::scene::LightType::Spot));
  checkNear(s.lights[0].position, glm::vec3(0, 5, 0));
  checkNear(s.lights[0].direction, glm::vec3(0, -1, 0));
  CHECK(s.lights[0].outerConeAngle == doctest::Approx(0.5f));
  CHECK(s.lights[0].intensity == doctest::Approx(100.0f));
  CHECK(std::isinf(s.lights[0].range));
  CHECK((s.lights[1].type == pr::scene::LightType::Directional));
  checkNear(s.lights[1].direction, glm::vec3(0, 0, -1));
  REQUIRE(s.cameras.size() == 1);
  CHECK(s.cameras[0].name == "persp");
  checkNear(s.cameras[0].position(), glm::vec3(0, 0, 10));
  // The inherited 0.01 scale is stripped: the camera frame is orthonormal.
  CHECK(glm::length(glm::vec3(s.cameras[0].cameraToWorld[0])) == doctest::Approx(1.0f));
}

TEST_CASE("GltfLoader: an extension's index must be a whole number within int's range") {
  auto dir = pr::test::scratchDir("gltf_extension_index");
  for (const double light : {1e30, -1e30, 0.5}) {
    pr::test::GltfWriter w = pr::test::oneTriangle();
    w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}}};
    w.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}});
    w.doc["scenes"][0]["nodes"] = {0, 1};
    INFO("light index " << light);
    CHECK_THROWS_WITH_AS(loadQuiet(w.write(dir, "light_index.gltf")),
                         doctest::Contains("KHR_lights_punctual light is not a whole number within int's range"),
                         pr::InputError);
  }
  // A whole number written as a real (0.0) is still the index 0.
  pr::test::GltfWriter w = pr::test::oneTriangle();
  w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}}};
  w.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 0.0}}}}}});
  w.doc["scenes"][0]["nodes"] = {0, 1};
  CHECK(loadQuiet(w.write(dir, "light_real_zero.gltf")).lights.size() == 1);
}

TEST_CASE("GltfLoader: emissive triangles become area lights with their world area") {
  auto dir = pr::test::scratchDir("gltf_emissive");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  w.doc["materials"] = {{{"emissiveFactor", {1, 1, 1}}}};
  w.doc["meshes"][0]["primitives"][0]["material"] = 0;
  w.doc["nodes"][0]["scale"] = {2, 3, 1};  // area 0.5 * 2 * 3 = 3
  Scene s = loadQuiet(w.write(dir, "emissive.gltf"));
  REQUIRE(s.areaLights.size() == 1);
  CHECK(s.areaLights[0].area == doctest::Approx(3.0f));
}

TEST_CASE("GltfLoader: EmissiveStrengthTest keeps emissive strengths above 1") {
  if (!pr::test::haveSharedScenes()) return;
  Scene emissive = loadQuiet(pr::test::sharedScenes() / "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb");
  float maxStrength = 0.0f;
  for (const auto& m : emissive.materials) maxStrength = std::max(maxStrength, m.emissiveStrength);
  CHECK(maxStrength == doctest::Approx(16.0f));
  CHECK(!emissive.areaLights.empty());
}

TEST_CASE("GltfLoader: an unknown optional extension is ignored with a warning") {
  auto dir = pr::test::scratchDir("gltf_optional_ext");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  w.doc["extensionsUsed"] = {"EXT_made_up"};
  Scene s = loadQuiet(w.write(dir, "optional.gltf"));
  CHECK(s.triangles.size() == 1);
  REQUIRE(s.warnings.size() == 1);
  CHECK(s.warnings[0].find("EXT_made_up") != std::string::npos);
}

TEST_CASE("GltfLoader: every bad input throws one InputError naming the file and the problem") {
  auto dir = pr::test::scratchDir("gltf_bad_inputs");
  for (const auto& bad : pr::test::writeBadInputs(dir)) {
    SUBCASE(bad.name.c_str()) {
      std::string message;
      try {
        pr::scene::LoadOptions options;
        if (bad.maxMemory) options.maxMemoryBytes = bad.maxMemory;
        pr::setQuiet(true);
        pr::scene::loadGltf(bad.path, options);
      } catch (const pr::InputError& e) {
        message = e.what();
      }
      pr::setQuiet(false);
      INFO("message: " << message);
      CHECK(message.find(bad.path.string()) != std::string::npos);
      CHECK(message.find(bad.expected) != std::string::npos);
    }
  }
}

TEST_CASE("GltfLoader: only triangles over non-black emissive texels become area lights") {
  auto dir = pr::test::scratchDir("gltf_emissive_texture");
  pr::test::GltfWriter w;
  // 8x1 emissive texture: texels 0-3 black, 4-7 white; emission = factor * texture.
  std::vector<uint8_t> texels;
  for (int x = 0; x < 8; ++x) texels.insert(texels.end(), {uint8_t(x < 4 ? 0 : 255), uint8_t(x < 4 ? 0 : 255), uint8_t(x < 4 ? 0 : 255), 255});
  auto png = pr::test::encodePng(8, 1, texels);
  w.doc["images"] = {{{"uri", "data:image/png;base64," + pr::test::base64(png)}}};
  w.doc["samplers"] = {{{"magFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}}};
  w.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  w.doc["materials"] = {{{"emissiveFactor", {1, 1, 1}}, {"emissiveTexture", {{"index", 0}}}}};
  // Two triangles: UVs within u 0..0.2 (texels 0-1, black even one texel beyond) and within
  // u 0.7..0.9 (white).
  int pos = w.addFloats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1}, "VEC3");
  int uv = w.addFloats({0.0f, 0.5f, 0.2f, 0.5f, 0.1f, 0.6f, 0.7f, 0.5f, 0.9f, 0.5f, 0.8f, 0.6f}, "VEC2");
  w.setRoots({w.addNode({{"mesh", w.addMesh({{"POSITION", pos}, {"TEXCOORD_0", uv}}, -1, 4, 0)}})});
  Scene s = loadQuiet(w.write(dir, "emissive_texture.gltf"));
  REQUIRE(s.triangles.size() == 2);
  REQUIRE(s.areaLights.size() == 1);
  CHECK(s.areaLights[0].triangle == 1);
  // The PNG decoded to the texels written (row 0 on top, RGBA).
  REQUIRE(s.textures.size() == 1);
  CHECK(s.textures[0].width == 8);
  CHECK(s.textures[0].rgba8 == texels);
}

TEST_CASE("GltfLoader: sparse accessors substitute values, with or without a base bufferView") {
  auto dir = pr::test::scratchDir("gltf_sparse");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  // Sparse on POSITION: element 1 becomes (5, 5, 0). UNSIGNED_BYTE index, as the spec allows.
  uint8_t index[1] = {1};
  float value[3] = {5, 5, 0};
  int indexView = w.addView(index, 1);
  int valueView = w.addView(value, sizeof value);
  w.doc["accessors"][0]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", indexView}, {"componentType", 5121}}},
                                     {"values", {{"bufferView", valueView}}}};
  // A sparse-only TEXCOORD_0 (no bufferView): zeros except element 2 = (0.5, 0.25).
  float uvValue[2] = {0.5f, 0.25f};
  uint8_t uvIndex[1] = {2};
  int uvIndexView = w.addView(uvIndex, 1);
  int uvValueView = w.addView(uvValue, sizeof uvValue);
  int uv = w.addAccessor(-1, 5126, 3, "VEC2");
  w.doc["accessors"][uv]["sparse"] = {{"count", 1},
                                      {"indices", {{"bufferView", uvIndexView}, {"componentType", 5121}}},
                                      {"values", {{"bufferView", uvValueView}}}};
  w.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
  Scene s = loadQuiet(w.write(dir, "sparse.gltf"));
  checkNear(s.positions[0], glm::vec3(0, 0, 0));
  checkNear(s.positions[1], glm::vec3(5, 5, 0));
  checkNear(s.positions[2], glm::vec3(0, 1, 0));
  CHECK(s.uvs[0] == glm::vec2(0.0f));
  CHECK(s.uvs[2] == glm::vec2(0.5f, 0.25f));

  // A sparse index past the accessor's count is bad input.
  index[0] = 9;
  pr::test::GltfWriter bad = pr::test::oneTriangle();
  int badIndexView = bad.addView(index, 1);
  int badValueView = bad.addView(value, sizeof value);
  bad.doc["accessors"][0]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", badIndexView}, {"componentType", 5121}}},
                                       {"values", {{"bufferView", badValueView}}}};
  CHECK_THROWS_WITH_AS(loadQuiet(bad.write(dir, "bad_sparse.gltf")), doctest::Contains("sparse index 9 is out of range"),
                       pr::InputError);
  pr::setQuiet(false);
}

TEST_CASE("GltfLoader: integer component types convert as values or, when normalized, to [-1, 1]") {
  auto dir = pr::test::scratchDir("gltf_component_types");
  pr::test::GltfWriter w;
  // POSITION as SHORT values (KHR_mesh_quantization style): plain integers, not normalized.
  std::vector<int16_t> pos = {0, 0, 0, 2, 0, 0, 0, -3, 0, 0};  // 3 x VEC3 + padding
  int posAcc = w.addAccessor(w.addView(pos.data(), pos.size() * 2), 5122, 3, "VEC3");
  // NORMAL as normalized BYTE: -128 clamps to -1 (spec 3.11: max(c / 127, -1)).
  std::vector<int8_t> nrm = {0, 0, -128, 0, 0, -127, 0, 0, -64, 0, 0, 0};
  int nrmAcc = w.addAccessor(w.addView(nrm.data(), nrm.size()), 5120, 3, "VEC3", 0, true);
  // TEXCOORD_0 as normalized SHORT.
  std::vector<int16_t> uv = {32767, -32768, 0, 16384, 0, 0};
  int uvAcc = w.addAccessor(w.addView(uv.data(), uv.size() * 2), 5122, 3, "VEC2", 0, true);
  // Indices as UNSIGNED_BYTE and, in a second instance below, UNSIGNED_INT.
  std::vector<uint8_t> idx8 = {0, 1, 2, 0};  // 3 indices + padding
  int idxAcc = w.addAccessor(w.addView(idx8.data(), idx8.size()), 5121, 3, "SCALAR");
  std::vector<uint32_t> idx32 = {0, 1, 2};
  int idx32Acc = w.addAccessor(w.addView(idx32.data(), idx32.size() * 4), 5125, 3, "SCALAR");
  nlohmann::json attributes = {{"POSITION", posAcc}, {"NORMAL", nrmAcc}, {"TEXCOORD_0", uvAcc}};
  int meshA = w.addMesh(attributes, idxAcc);
  int meshB = w.addMesh(attributes, idx32Acc);
  w.setRoots({w.addNode({{"mesh", meshA}}), w.addNode({{"mesh", meshB}})});
  Scene s = loadQuiet(w.write(dir, "component_types.gltf"));
  REQUIRE(s.positions.size() == 6);
  checkNear(s.positions[1], glm::vec3(2, 0, 0));
  checkNear(s.positions[2], glm::vec3(0, -3, 0));
  checkNear(s.normals[0], glm::vec3(0, 0, -1));
  checkNear(s.normals[2], glm::vec3(0, 0, -1));  // normalised after decoding -64/127
  CHECK(s.uvs[0].x == doctest::Approx(1.0f));
  CHECK(s.uvs[0].y == doctest::Approx(-1.0f));
  CHECK(s.uvs[1].y == doctest::Approx(16384.0f / 32767.0f));
  REQUIRE(s.triangles.size() == 2);
  CHECK(s.triangles[1].v[2] == 3 + 2);  // the UNSIGNED_INT instance, offset by its base vertex
  // (0,0,0), (2,0,0), (0,-3,0): cross((2,0,0), (0,-3,0)) = (0,0,-6), facing -Z like NORMAL.
  checkNear(windingNormal(s, 0), glm::vec3(0, 0, -1));
  CHECK(s.colors.empty());  // no primitive has COLOR_0
}
