// Statistics of a render-ready scene: what `parrender info` prints and what run records and
// reports quote to describe the workload (triangles, lights, textures, memory).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "common/scene/scene.h"

namespace pr::scene {

struct SceneStats {
  std::string file;
  size_t triangles = 0;
  size_t vertices = 0;
  size_t objects = 0;
  size_t materials = 0;                       // materials used by at least one triangle
  std::array<size_t, 5> materialsByKind{};    // indexed by MaterialKind, used materials only
  size_t pointLights = 0, spotLights = 0, directionalLights = 0;
  size_t areaLightTriangles = 0;              // emissive triangles with non-zero area
  double emissiveArea = 0.0;                  // their total world area, m^2
  size_t textures = 0;                        // textures with image data
  size_t texels = 0;                          // sum of width * height over those
  size_t cameras = 0;
  Bounds bounds;
  std::vector<std::string> extensionsUsed;
  std::vector<std::string> warnings;
  size_t memoryBytes = 0;                     // Scene::memoryBytes()
};

SceneStats computeStats(const Scene& scene);

}  // namespace pr::scene
