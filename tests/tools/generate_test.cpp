// Tests of `parrender generate` (tools/cmd_generate.cpp and tools/scenegen/): the committed
// scenes are reproduced byte for byte, the files parse with tinygltf and hold what
// scenes/README.md promises (materials, lights, camera, triangle counts), and bad arguments
// exit with status 2. Files are parsed with tinygltf directly, independent of the loader.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {

std::string readBytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << file.rdbuf();
  return bytes.str();
}

tinygltf::Model loadModel(const fs::path& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = path.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, path.string())
                                       : loader.LoadASCIIFromFile(&model, &err, &warn, path.string());
  INFO(err);
  REQUIRE(ok);
  return model;
}

const tinygltf::Material* findMaterial(const tinygltf::Model& m, const std::string& name) {
  for (const auto& mat : m.materials)
    if (mat.name == name) return &mat;
  return nullptr;
}

const tinygltf::Node* findNode(const tinygltf::Model& m, const std::string& name) {
  for (const auto& node : m.nodes)
    if (node.name == name) return &node;
  return nullptr;
}

double extensionNumber(const tinygltf::Material& mat, const std::string& ext, const std::string& key) {
  auto it = mat.extensions.find(ext);
  if (it == mat.extensions.end() || !it->second.Has(key)) return -1.0;
  return it->second.Get(key).GetNumberAsDouble();
}

size_t meshTriangles(const tinygltf::Model& m, int mesh) {
  size_t n = 0;
  for (const auto& prim : m.meshes.at(mesh).primitives) n += m.accessors.at(prim.indices).count / 3;
  return n;
}

glm::vec3 vec3Of(const std::vector<double>& v, glm::vec3 fallback = glm::vec3(0.0f)) {
  return v.size() == 3 ? glm::vec3(v[0], v[1], v[2]) : fallback;
}

// Generates into a scratch file and returns its path; the command must succeed.
fs::path generate(const std::string& scratch, const std::string& file, const std::string& args) {
  fs::path out = pr::test::scratchDir(scratch) / file;
  auto result = pr::test::runParrender("generate " + args + " -o \"" + out.string() + "\"");
  INFO(result.output);
  REQUIRE(result.exitStatus == 0);
  REQUIRE(fs::is_regular_file(out));
  return out;
}

}  // namespace

TEST_CASE("Generate: regenerating each committed scene reproduces it byte for byte") {
  for (const char* name : {"cornell", "cornell-diffuse", "cornell-glass", "cornell-rough", "hotspot"}) {
    CAPTURE(name);
    const fs::path committed = pr::test::sourceDir() / "scenes" / (std::string(name) + ".gltf");
    REQUIRE(fs::is_regular_file(committed));
    CHECK(fs::file_size(committed) < 1024 * 1024);
    fs::path out = generate(std::string("generate_repro_") + name, std::string(name) + ".gltf", name);
    CHECK(readBytes(out) == readBytes(committed));
  }
}

TEST_CASE("Generate: cornell has a glass and a mirror sphere, an emissive light and a camera") {
  auto m = loadModel(generate("generate_cornell", "cornell.gltf", "cornell"));
  const auto* glass = findMaterial(m, "glass");
  REQUIRE(glass);
  CHECK(extensionNumber(*glass, "KHR_materials_transmission", "transmissionFactor") == 1.0);
  CHECK(extensionNumber(*glass, "KHR_materials_ior", "ior") == 1.5);
  CHECK(glass->pbrMetallicRoughness.roughnessFactor == 0.0);
  CHECK(glass->pbrMetallicRoughness.baseColorFactor == std::vector<double>{1, 1, 1, 1});

  const auto* mirror = findMaterial(m, "mirror");
  REQUIRE(mirror);
  CHECK(mirror->pbrMetallicRoughness.metallicFactor == 1.0);
  CHECK(mirror->pbrMetallicRoughness.roughnessFactor == 0.0);

  // The walls are purely Lambertian, as the glTF spec writes it: no dielectric Fresnel layer.
  for (const char* wall : {"white", "red", "green"}) {
    const auto* paint = findMaterial(m, wall);
    REQUIRE(paint);
    CHECK(extensionNumber(*paint, "KHR_materials_specular", "specularFactor") == 0.0);
  }
  CHECK(glass->extensions.count("KHR_materials_specular") == 0);

  const auto* light = findMaterial(m, "light");
  REQUIRE(light);
  CHECK(light->emissiveFactor == std::vector<double>{1, 1, 1});
  CHECK(extensionNumber(*light, "KHR_materials_emissive_strength", "emissiveStrength") > 1.0);

  // Walls: red left (x = 0) and green right, the light quad faces down into the box.
  CHECK(findMaterial(m, "red")->pbrMetallicRoughness.baseColorFactor[0] > 0.5);
  CHECK(findMaterial(m, "green")->pbrMetallicRoughness.baseColorFactor[1] > 0.4);
  const auto* lightNode = findNode(m, "light");
  REQUIRE(lightNode);
  const auto& lightPrim = m.meshes.at(lightNode->mesh).primitives.at(0);
  const auto& normalAcc = m.accessors.at(lightPrim.attributes.at("NORMAL"));
  const auto& view = m.bufferViews.at(normalAcc.bufferView);
  const float* n = reinterpret_cast<const float*>(&m.buffers.at(view.buffer).data.at(view.byteOffset));
  CHECK(n[1] == doctest::Approx(-1.0f));

  // Spheres: ~2-5k smooth-shaded triangles each, resting on the floor.
  for (const char* sphere : {"glass sphere", "mirror sphere"}) {
    const auto* node = findNode(m, sphere);
    REQUIRE(node);
    CHECK(meshTriangles(m, node->mesh) >= 2000);
    CHECK(meshTriangles(m, node->mesh) <= 5000);
    CHECK(m.meshes[node->mesh].primitives[0].attributes.count("NORMAL") == 1);
    CHECK(vec3Of(node->translation).y == doctest::Approx(1.0f));
  }
  CHECK(m.materials.at(m.meshes.at(findNode(m, "glass sphere")->mesh).primitives[0].material).name == "glass");

  REQUIRE(m.cameras.size() == 1);
  CHECK(m.cameras[0].type == "perspective");
  const auto* camera = findNode(m, "camera");
  REQUIRE(camera);
  CHECK(camera->camera == 0);
  CHECK(vec3Of(camera->translation).z > 5.6f);  // in front of the open box
}

TEST_CASE("Generate: cornell-diffuse has the same box with white diffuse spheres and no glass") {
  auto m = loadModel(generate("generate_cornell_diffuse", "cornell-diffuse.gltf", "cornell-diffuse"));
  CHECK(findMaterial(m, "glass") == nullptr);
  CHECK(findMaterial(m, "mirror") == nullptr);
  for (const auto& mat : m.materials) {
    CHECK(mat.extensions.count("KHR_materials_transmission") == 0);
    CHECK(mat.pbrMetallicRoughness.metallicFactor == 0.0);
  }
  for (const char* sphere : {"front sphere", "back sphere"}) {
    const auto* node = findNode(m, sphere);
    REQUIRE(node);
    const auto& mat = m.materials.at(m.meshes.at(node->mesh).primitives[0].material);
    CHECK(mat.pbrMetallicRoughness.roughnessFactor == 1.0);
    CHECK(mat.pbrMetallicRoughness.baseColorFactor[0] == mat.pbrMetallicRoughness.baseColorFactor[2]);
  }
  CHECK(findNode(m, "light") != nullptr);
  CHECK(m.cameras.size() == 1);
}

TEST_CASE("Generate: cornell-glass has the box with the glass sphere in front and a white diffuse one behind") {
  auto m = loadModel(generate("generate_cornell_glass", "cornell-glass.gltf", "cornell-glass"));
  CHECK(findMaterial(m, "mirror") == nullptr);
  const auto* glass = findNode(m, "glass sphere");
  const auto* back = findNode(m, "back sphere");
  REQUIRE(glass);
  REQUIRE(back);
  const auto& glassMaterial = m.materials.at(m.meshes.at(glass->mesh).primitives[0].material);
  CHECK(glassMaterial.extensions.count("KHR_materials_transmission") == 1);
  const auto& backMaterial = m.materials.at(m.meshes.at(back->mesh).primitives[0].material);
  CHECK(backMaterial.extensions.count("KHR_materials_transmission") == 0);
  CHECK(backMaterial.extensions.count("KHR_materials_specular") == 1);  // specularFactor 0: Lambertian
  CHECK(backMaterial.pbrMetallicRoughness.metallicFactor == 0.0);
  CHECK(findNode(m, "light") != nullptr);
  CHECK(m.cameras.size() == 1);
}

TEST_CASE("Generate: cornell-rough has a rough metal block standing on the floor and a frosted, partly transmissive sphere") {
  auto m = loadModel(generate("generate_cornell_rough", "cornell-rough.gltf", "cornell-rough"));
  const auto* block = findNode(m, "metal block");
  const auto* sphere = findNode(m, "frosted sphere");
  REQUIRE(block);
  REQUIRE(sphere);
  const auto& metal = m.materials.at(m.meshes.at(block->mesh).primitives[0].material);
  CHECK(metal.pbrMetallicRoughness.metallicFactor == 1.0);
  CHECK(metal.pbrMetallicRoughness.roughnessFactor == doctest::Approx(0.3));
  const auto& frosted = m.materials.at(m.meshes.at(sphere->mesh).primitives[0].material);
  CHECK(frosted.pbrMetallicRoughness.roughnessFactor == doctest::Approx(0.3));
  CHECK(extensionNumber(frosted, "KHR_materials_transmission", "transmissionFactor") == doctest::Approx(0.8));
  // The block: 12 triangles, its base on the floor (y = 0) and its top 3.30 up, inside the box.
  const auto& accessor = m.accessors.at(std::size_t(m.meshes.at(block->mesh).primitives[0].attributes.at("POSITION")));
  REQUIRE(accessor.minValues.size() == 3);
  CHECK(accessor.minValues[1] == doctest::Approx(0.0));
  CHECK(accessor.maxValues[1] == doctest::Approx(3.30));
  CHECK(m.accessors.at(std::size_t(m.meshes.at(block->mesh).primitives[0].indices)).count == 36);
  CHECK(findMaterial(m, "mirror") == nullptr);
  CHECK(m.cameras.size() == 1);
}

TEST_CASE("Generate: landscape --size 8 has 2*8*8 terrain triangles plus the light and the lens") {
  auto m = loadModel(generate("generate_landscape", "landscape.glb", "landscape --size 8"));
  const auto* terrain = findNode(m, "terrain");
  const auto* lens = findNode(m, "lens");
  const auto* light = findNode(m, "light");
  REQUIRE(terrain);
  REQUIRE(lens);
  REQUIRE(light);
  CHECK(meshTriangles(m, terrain->mesh) == 2 * 8 * 8);
  CHECK(m.accessors.at(m.meshes[terrain->mesh].primitives[0].attributes.at("POSITION")).count == 9 * 9);
  const auto& lensMat = m.materials.at(m.meshes.at(lens->mesh).primitives[0].material);
  CHECK(extensionNumber(lensMat, "KHR_materials_transmission", "transmissionFactor") == 1.0);
  CHECK(extensionNumber(lensMat, "KHR_materials_ior", "ior") == 1.5);
  const auto& lightMat = m.materials.at(m.meshes.at(light->mesh).primitives[0].material);
  CHECK(extensionNumber(lightMat, "KHR_materials_emissive_strength", "emissiveStrength") > 1.0);

  // The lens lies between light and terrain: its box is below the light's and above the terrain's.
  auto boxOf = [&](const tinygltf::Node* node) {
    const auto& acc = m.accessors.at(m.meshes.at(node->mesh).primitives[0].attributes.at("POSITION"));
    return std::make_pair(vec3Of(acc.minValues), vec3Of(acc.maxValues));
  };
  auto [lensMin, lensMax] = boxOf(lens);
  CHECK(lensMax.y < boxOf(light).first.y);
  CHECK(lensMin.y > boxOf(terrain).second.y);
  CHECK(lensMax.x - lensMin.x > 2.0f * (lensMax.y - lensMin.y));  // lens-shaped: flattened
  CHECK(m.nodes.size() == 4);  // terrain, lens, light, camera
  CHECK(m.cameras.size() == 1);
}

TEST_CASE("Generate: the landscape seed changes the terrain and only the terrain") {
  const std::string a = readBytes(generate("generate_seed_a", "a.glb", "landscape --size 4 --seed 1"));
  const std::string b = readBytes(generate("generate_seed_b", "b.glb", "landscape --size 4 --seed 1"));
  const std::string c = readBytes(generate("generate_seed_c", "c.glb", "landscape --size 4 --seed 2"));
  CHECK(a == b);
  CHECK(a != c);
  CHECK(a.size() == c.size());
}

TEST_CASE("Generate: hotspot puts its sphere cluster in the top-left of the camera's view") {
  auto m = loadModel(generate("generate_hotspot", "hotspot.gltf", "hotspot"));
  const auto* cameraNode = findNode(m, "camera");
  REQUIRE(cameraNode);
  const auto& cam = m.cameras.at(cameraNode->camera).perspective;
  const glm::vec3 eye = vec3Of(cameraNode->translation);
  glm::quat q(1, 0, 0, 0);
  if (cameraNode->rotation.size() == 4)
    q = glm::quat(float(cameraNode->rotation[3]), float(cameraNode->rotation[0]), float(cameraNode->rotation[1]),
                  float(cameraNode->rotation[2]));
  const float tanHalf = std::tan(float(cam.yfov) / 2.0f);

  int spheres = 0, specular = 0;
  size_t sphereTriangles = 0, otherTriangles = 0;
  for (const auto& node : m.nodes) {
    if (node.mesh < 0) continue;
    if (node.name.rfind("sphere", 0) != 0) {
      otherTriangles += meshTriangles(m, node.mesh);
      continue;
    }
    ++spheres;
    sphereTriangles += meshTriangles(m, node.mesh);
    const auto& mat = m.materials.at(m.meshes.at(node.mesh).primitives[0].material);
    specular += mat.name == "glass" || mat.name == "mirror";
    // Camera space (glTF cameras look down -z): normalised device x < 0 is left, y > 0 is top.
    glm::vec3 p = glm::inverse(q) * (vec3Of(node.translation) - eye);
    REQUIRE(p.z < 0.0f);
    float ndcX = p.x / (-p.z * tanHalf * float(cam.aspectRatio)), ndcY = p.y / (-p.z * tanHalf);
    CHECK(ndcX < -0.2f);
    CHECK(ndcX > -1.0f);
    CHECK(ndcY > 0.2f);
    CHECK(ndcY < 1.0f);
  }
  CHECK(spheres >= 40);
  CHECK(specular > 0);
  CHECK(sphereTriangles > 50 * otherTriangles);  // nearly all geometry in the cluster
  REQUIRE(m.lights.size() == 1);
  CHECK(m.lights[0].type == "point");
  const auto* area = findNode(m, "area light");
  REQUIRE(area);
  CHECK(m.materials.at(m.meshes.at(area->mesh).primitives[0].material).emissiveFactor == std::vector<double>{1, 1, 1});
}

TEST_CASE("Generate: bad arguments exit 2 with a message naming the problem") {
  auto dir = pr::test::scratchDir("generate_errors");
  const std::string out = " -o \"" + (dir / "x.gltf").string() + "\"";
  // A file where the output's folder would have to be.
  const fs::path blocker = pr::test::scratchDir("generate_errors_blocker") / "blocker";
  std::ofstream(blocker) << "not a folder";
  struct Case {
    std::string args, expect;
  };
  for (const Case& c : {Case{"generate nosuchscene" + out, "nosuchscene"},
                        Case{"generate landscape --size 0" + out, "--size 0"},
                        Case{"generate cornell --size 100000" + out, "--size 100000"},
                        Case{"generate cornell --seed 3" + out, "--seed"},
                        Case{"generate cornell -o \"" + (dir / "x.obj").string() + "\"", ".obj"},
                        Case{"generate cornell -o \"" + (blocker / "x.gltf").string() + "\"", "cannot make the folder"},
                        Case{"generate cornell", "--output"},
                        Case{"generate cornell --size many" + out, "many"}}) {
    CAPTURE(c.args);
    auto result = pr::test::runParrender(c.args);
    CHECK(result.exitStatus == 2);
    CHECK(result.output.find(c.expect) != std::string::npos);
  }
  // Nothing was written, not even a temporary file.
  CHECK(fs::is_empty(dir));
}

TEST_CASE("Generate: the output's missing folders are made") {
  const fs::path out = pr::test::scratchDir("generate_folders") / "scenes" / "deeper" / "box.gltf";
  auto result = pr::test::runParrender("generate cornell -o \"" + out.string() + "\"");
  INFO(result.output);
  CHECK(result.exitStatus == 0);
  CHECK(fs::is_regular_file(out));
}

TEST_CASE("Generate: --help lists every scene with its description") {
  auto result = pr::test::runParrender("generate --help");
  CHECK(result.exitStatus == 0);
  for (const char* name : {"cornell", "cornell-diffuse", "landscape", "hotspot"}) CHECK(result.output.find(name) != std::string::npos);
  CHECK(result.output.find("Jensen") != std::string::npos);
}
