// Loading glTF 2.0 (.gltf with external or data: buffers, .glb) into the render-ready Scene.
// Every problem with the file throws pr::InputError naming the file and element.
#pragma once

#include <filesystem>

#include "common/scene/scene.h"

namespace pr::scene {

// Loads the file's default scene (scene 0 when none is marked), flattened to world space.
Scene loadGltf(const std::filesystem::path& path);

}  // namespace pr::scene
