// The render-ready scene every renderer reads: flat world-space vertex and triangle arrays
// with material ids, the grouping of triangles into objects (glTF mesh primitives, needed by
// object partitioning), materials, textures, lights and cameras. Built by gltf_loader.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/camera.h"
#include "common/scene/environment.h"
#include "common/scene/light.h"
#include "common/scene/material.h"
#include "common/scene/texture.h"

namespace pr::scene {

// Largest vertex and triangle counts of a scene: indices are uint32_t, and UINT32_MAX stays
// free. The loader refuses more with an input error naming the count.
inline constexpr uint64_t kMaxVertices = uint64_t(UINT32_MAX) - 1;
inline constexpr uint64_t kMaxTriangles = uint64_t(UINT32_MAX) - 1;

struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::infinity()};
  glm::vec3 max{-std::numeric_limits<float>::infinity()};
  void extend(glm::vec3 p) { min = glm::min(min, p); max = glm::max(max, p); }
  void extend(const Bounds& b) { min = glm::min(min, b.min); max = glm::max(max, b.max); }
  bool empty() const { return min.x > max.x; }
  glm::vec3 extent() const { return empty() ? glm::vec3(0.0f) : max - min; }
  glm::vec3 center() const { return 0.5f * (min + max); }
};

// Three vertex indices (counter-clockwise seen from the front, after any mirroring fix) and a
// material id into Scene::materials.
struct Triangle {
  uint32_t v[3];
  uint32_t material;
};

// One drawn glTF mesh primitive (one node instance of it): a contiguous triangle range.
struct Object {
  std::string name;  // "node/mesh#primitive"
  int node = -1, mesh = -1, primitive = -1;
  uint32_t firstTriangle = 0;
  uint32_t triangleCount = 0;
  Bounds bounds;
};

struct Scene {
  std::filesystem::path source;  // the file it was loaded from (empty when built in code)

  // Vertices, world space. normals are unit length (generated, area-weighted, when absent);
  // uvs is UV set 0 (zero when absent); colors is COLOR_0 (1 where a primitive has none),
  // empty when no primitive has it.
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::vec4> colors;
  // Per-vertex tangents (w = bitangent handedness) for normal mapping; empty when no material
  // has a normal map, zero on vertices of primitives without one (common/scene/tangent_frame.h).
  std::vector<glm::vec4> tangents;

  std::vector<Triangle> triangles;
  std::vector<Object> objects;
  std::vector<Material> materials;  // always at least one: the glTF default material is last
  std::vector<Texture> textures;
  std::vector<PunctualLight> lights;
  // Light from infinitely far away (--env, or the default light of a scene without lights);
  // none when null. Shared read-only.
  std::shared_ptr<const Environment> environment;
  std::vector<AreaLight> areaLights;  // emissive triangles
  std::vector<Camera> cameras;        // the file's cameras in node order; may be empty

  Bounds bounds;
  std::vector<std::string> extensionsUsed;  // as listed by the file
  std::vector<std::string> variants;        // KHR_materials_variants names, in file order
  std::string variant;                      // the one applied (empty: the default materials)
  std::vector<std::string> warnings;        // optional content that was skipped or ignored

  // Bytes held by the arrays above (the render-ready layout), textures included.
  size_t memoryBytes() const;
  // The part of it that is geometry: vertex arrays, triangles and objects (what a partitioned
  // method distributes rather than replicates).
  size_t geometryBytes() const;
};

}  // namespace pr::scene
