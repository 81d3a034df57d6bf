// `parrender generate NAME -o FILE [--size N] [--seed S]`: writes one of the bundled scenes
// (tools/scenegen/scene_registry.h) as glTF 2.0, .gltf with an embedded buffer or .glb by the
// output's extension. Same arguments, byte-identical file: the committed scenes/ are its output.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "tools/commands.h"
#include "tools/scenegen/scene_registry.h"

namespace pr::cli {
namespace {

struct GenerateOptions {
  std::string scene;
  std::string output;
  int size = 0;
  uint64_t seed = 0;
  CLI::Option* sizeOption = nullptr;
  CLI::Option* seedOption = nullptr;
};

std::string sceneListHelp() {
  std::string text = "Writes a bundled scene as glTF 2.0 (.gltf with the buffer embedded, or .glb).\nScenes:";
  size_t column = 0;  // the names' width, so that the descriptions line up
  for (const scenegen::SceneEntry& entry : scenegen::sceneRegistry()) column = std::max(column, entry.name.size() + 2);
  for (const scenegen::SceneEntry& entry : scenegen::sceneRegistry()) {
    const scenegen::SceneProperties& scene = entry.properties;
    text += "\n  " + entry.name + std::string(column - entry.name.size(), ' ') + entry.description + "\n" +
            std::string(column + 2, ' ') + "--size: " + std::string(scene.sizeMeaning) +
            " (default " + std::to_string(scene.defaultSize) + ", " + std::to_string(scene.minSize) + " to " +
            std::to_string(scene.maxSize) + ")" + (scene.usesSeed ? "; --seed default " + std::to_string(scene.defaultSeed) : "");
  }
  return text;
}

void runGenerate(const GenerateOptions& options) {
  const scenegen::SceneEntry& entry = scenegen::findScene(options.scene);
  const scenegen::SceneProperties& scene = entry.properties;
  if (options.seedOption->count() > 0 && !scene.usesSeed)
    throw InputError("--seed has no effect on scene '" + entry.name + "' (it has no random content)");

  std::string ext = std::filesystem::path(options.output).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".gltf" && ext != ".glb")
    throw InputError("output file '" + options.output + "': unsupported extension '" +
                     std::filesystem::path(options.output).extension().string() + "' (expected .gltf or .glb)");

  scenegen::SceneParams params;
  params.size = options.sizeOption->count() > 0 ? options.size : scene.defaultSize;
  params.seed = options.seedOption->count() > 0 ? options.seed : scene.defaultSeed;
  const scenegen::GltfBuilder builder = scenegen::generateScene(entry, params);
  const std::string bytes = builder.serialize(ext == ".glb");
  // A folder that does not exist yet is made, as `report -o` does (build/scenes/ on a fresh clone).
  const std::filesystem::path parent = std::filesystem::absolute(options.output).parent_path();
  std::error_code made;
  std::filesystem::create_directories(parent, made);
  if (!std::filesystem::is_directory(parent))
    throw InputError("output file '" + options.output + "': cannot make the folder " + parent.string() +
                     (made ? " (" + made.message() + ")" : std::string()));
  writeFileAtomically(options.output, bytes, "scene file");
  std::printf("wrote %s: scene %s, %zu triangles, %zu bytes\n", options.output.c_str(), entry.name.c_str(),
              builder.triangleCount(), bytes.size());
}

}  // namespace

void addGenerateCommand(CLI::App& app) {
  auto options = std::make_shared<GenerateOptions>();
  CLI::App* cmd = app.add_subcommand("generate", "write a bundled scene (cornell, cornell-diffuse, landscape, hotspot, stress-*) as glTF");
  cmd->footer(sceneListHelp());
  cmd->add_option("scene", options->scene, "scene name (listed below)")->required();
  cmd->add_option("-o,--output", options->output, "output file, .gltf (embedded buffer) or .glb (binary)")->required();
  options->sizeOption = cmd->add_option("--size", options->size, "scene detail; meaning and range per scene below");
  options->seedOption = cmd->add_option("--seed", options->seed, "random seed (landscape, hotspot)");
  cmd->callback([options] {
    requireOneRank("generate");
    runGenerate(*options);
  });
}

}  // namespace pr::cli
