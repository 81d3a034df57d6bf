// File names and URIs as users' files have them (unicode, spaces, percent-encoding, '+',
// folders) load; GLB containers with chunks the spec says to skip load. The refusals (URIs
// escaping the folder, bad base64, a .glb as a buffer, a GLB without BIN) are in the bad-input
// catalogue (gltf_writer.h).
#include <doctest/doctest.h>

#include <fstream>

#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "tests/common/scene/gltf_writer.h"
#include "tests/test_support.h"

namespace {

using pr::scene::Scene;

// Writes the one-triangle file with its buffer in `bufferFile` (referred to by `uri`).
std::filesystem::path writeWithExternalBuffer(const std::filesystem::path& gltf, const std::filesystem::path& bufferFile,
                                              const std::string& uri) {
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::filesystem::create_directories(bufferFile.parent_path());
  std::filesystem::create_directories(gltf.parent_path());
  std::ofstream(bufferFile, std::ios::binary).write(reinterpret_cast<const char*>(positions), sizeof positions);
  return pr::test::oneTriangleWithBufferUri(gltf.parent_path(), gltf.filename().string(), uri);
}

Scene loadQuiet(const std::filesystem::path& path) {
  pr::setQuiet(true);
  Scene scene = pr::scene::loadGltf(path);
  pr::setQuiet(false);
  return scene;
}

}  // namespace

TEST_CASE("GltfPaths: unicode, spaces, percent-encoding and '+' in file names and URIs load") {
  auto dir = pr::test::scratchDir("gltf_paths") / "モデル folder";
  struct Case {
    const char* name;
    const char* gltf;
    const char* bufferFile;
    const char* uri;
  };
  const Case cases[] = {
      {"percent-encoded UTF-8 and spaces", "données ü.gltf", "données ü.bin", "donn%C3%A9es%20%C3%BC.bin"},
      {"raw UTF-8 and spaces", "raw.gltf", "ràw naмe.bin", "ràw naмe.bin"},
      {"a literal '+'", "plus.gltf", "a+b.bin", "a+b.bin"},
      {"a subfolder and a '..' that stays inside", "sub.gltf", "bin/x.bin", "bin/../bin/x.bin"},
  };
  for (const Case& c : cases) {
    SUBCASE(c.name) {
      auto path = writeWithExternalBuffer(dir / c.gltf, dir / c.bufferFile, c.uri);
      Scene s = loadQuiet(path);
      CHECK(s.triangles.size() == 1);
      CHECK(s.positions.at(1) == glm::vec3(1, 0, 0));
    }
  }
  SUBCASE("a model in the working directory, named without a folder") {
    auto path = writeWithExternalBuffer(dir / "here.gltf", dir / "here.bin", "here.bin");
    const auto previous = std::filesystem::current_path();
    std::filesystem::current_path(dir);
    Scene s = loadQuiet("here.gltf");
    std::filesystem::current_path(previous);
    CHECK(s.triangles.size() == 1);
  }
}

TEST_CASE("GltfPaths: a buffer in the working directory but not beside the model is not found") {
  // tinygltf also probes "./uri"; the loader never reads from the working directory.
  auto dir = pr::test::scratchDir("gltf_paths_cwd");
  auto path = writeWithExternalBuffer(dir / "model" / "m.gltf", dir / "elsewhere.bin", "elsewhere.bin");
  const auto previous = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  std::string message;
  try {
    loadQuiet(path);
  } catch (const pr::InputError& e) {
    message = e.what();
  }
  std::filesystem::current_path(previous);
  CHECK(message.find("buffer file 'elsewhere.bin' is missing") != std::string::npos);
}

TEST_CASE("GltfPaths: a GLB with extra chunks of unknown type loads (spec 4.4.3.1: skipped)") {
  auto dir = pr::test::scratchDir("gltf_glb_chunks");
  auto path = pr::test::writeBytes(dir / "extra.glb", pr::test::oneTriangleGlb({{0x12345678u, "unknown chunk"}, {0x12345679u, ""}}));
  Scene s = loadQuiet(path);
  CHECK(s.triangles.size() == 1);
}

TEST_CASE("GltfPaths: the same bytes load from memory, and an external reference from memory is refused") {
  const std::vector<uint8_t> glb = pr::test::oneTriangleGlb();
  Scene s = pr::scene::loadGltfFromMemory(glb, "memory.glb");
  CHECK(s.triangles.size() == 1);
  auto dir = pr::test::scratchDir("gltf_memory_external");
  auto path = writeWithExternalBuffer(dir / "m.gltf", dir / "m.bin", "m.bin");
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK_THROWS_WITH_AS(pr::scene::loadGltfFromMemory(std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size()), "memory.gltf"),
                       doctest::Contains("memory.gltf: refers to the external file 'm.bin', but a model loaded from memory has no folder"),
                       pr::InputError);
}

TEST_CASE("GltfPaths: a node hierarchy 1000 levels deep loads (the limit, one more is refused)") {
  auto dir = pr::test::scratchDir("gltf_deep_hierarchy");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  w.doc["nodes"][0].erase("mesh");
  for (int i = 1; i <= 1000; ++i) {
    w.doc["nodes"][size_t(i - 1)]["children"] = {i};
    w.addNode(i == 1000 ? nlohmann::json{{"mesh", 0}, {"translation", {0.001, 0, 0}}}
                        : nlohmann::json{{"translation", {0.001, 0, 0}}});
  }
  Scene s = loadQuiet(w.write(dir, "deep.gltf"));
  REQUIRE(s.triangles.size() == 1);
  CHECK(s.positions[0].x == doctest::Approx(1.0f).epsilon(1e-4));  // 1000 translations of 0.001
}

TEST_CASE("GltfPaths: a long bad data URI is quoted in part, so the message stays one short line") {
  auto dir = pr::test::scratchDir("gltf_long_bad_uri");
  auto path = pr::test::oneTriangleWithBufferUri(dir, "long.gltf", "data:application/octet-stream;base64," + std::string(100000, '*'));
  std::string message;
  try {
    loadQuiet(path);
  } catch (const pr::InputError& e) {
    message = e.what();
  }
  CHECK(message.find("Failed to decode 'uri'") != std::string::npos);
  CHECK(message.find("characters)") != std::string::npos);
  CHECK(message.size() < 600);
  CHECK(message.find('\n') == std::string::npos);
}

TEST_CASE("GltfPaths: a link inside the folder that leads out of it is refused") {
  auto dir = pr::test::scratchDir("gltf_symlink_escape");
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::filesystem::create_directories(dir / "outside");
  std::ofstream(dir / "outside" / "secret.bin", std::ios::binary).write(reinterpret_cast<const char*>(positions), sizeof positions);
  std::filesystem::create_directories(dir / "model");
  std::filesystem::create_directory_symlink(dir / "outside", dir / "model" / "linked");
  std::filesystem::create_symlink(dir / "outside" / "secret.bin", dir / "model" / "file_link.bin");
  for (const char* uri : {"linked/secret.bin", "file_link.bin"}) {
    CAPTURE(uri);
    auto path = pr::test::oneTriangleWithBufferUri(dir / "model", "m.gltf", uri);
    CHECK_THROWS_WITH_AS(loadQuiet(path), doctest::Contains("outside the model's folder (or through a link out of it); refused"),
                         pr::InputError);
  }
}

TEST_CASE("GltfPaths: with a relative folder, tinygltf's working-directory probe is not answered either") {
  // Model m/x.gltf referring to "m/b.bin": only m/m/b.bin is its buffer; ./m/b.bin (which
  // exists) is the working-directory probe and must not be read.
  auto dir = pr::test::scratchDir("gltf_relative_probe");
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::filesystem::create_directories(dir / "m");
  std::ofstream(dir / "m" / "b.bin", std::ios::binary).write(reinterpret_cast<const char*>(positions), sizeof positions);
  pr::test::oneTriangleWithBufferUri(dir / "m", "x.gltf", "m/b.bin");
  const auto previous = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  std::string message;
  try {
    loadQuiet("m/x.gltf");
  } catch (const pr::InputError& e) {
    message = e.what();
  }
  std::filesystem::current_path(previous);
  CHECK(message.find("buffer file 'm/b.bin' is missing") != std::string::npos);
}
