// Loading glTF 2.0 (.gltf with external or data: buffers, .glb) into the render-ready Scene.
// Every problem with the file throws pr::InputError naming the file and element.
#pragma once

#include <filesystem>
#include <string>

#include "common/scene/scene.h"

namespace pr::scene {

struct LoadOptions {
  // KHR_materials_variants: the variant whose material mappings apply; empty = the default
  // materials. A name the file does not define is an input error listing the ones it does.
  std::string variant;
};

// Loads the file's default scene (scene 0 when none is marked), flattened to world space.
Scene loadGltf(const std::filesystem::path& path, const LoadOptions& options = {});

}  // namespace pr::scene
