// Loading glTF 2.0 (.gltf with external or data: buffers, .glb) into the render-ready Scene.
// Every problem with the file throws pr::InputError naming the file and element.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "common/scene/scene.h"
#include "common/util/memory_limit.h"

namespace pr::scene {

struct LoadOptions {
  // KHR_materials_variants: the variant whose material mappings apply; empty = the default
  // materials. A name the file does not define is an input error listing the ones it does.
  std::string variant;
  // What the load may allocate (the file, its buffers and images, decoded accessors, the
  // flattened scene); a file that needs more is refused before the allocation.
  uint64_t maxMemoryBytes = memoryLimit();
};

// Loads the file's default scene (scene 0 when none is marked), flattened to world space.
// Buffers and images it refers to are read from the file's folder; a URI that leads outside
// it (`../../etc/passwd`) is refused.
Scene loadGltf(const std::filesystem::path& path, const LoadOptions& options = {});

// The same from bytes in memory (.gltf JSON or .glb); `name` starts every message. Data URIs
// and a GLB's own buffer work; a reference to an external file is an input error.
Scene loadGltfFromMemory(std::span<const uint8_t> bytes, const std::string& name, const LoadOptions& options = {});

}  // namespace pr::scene
