// The `hotspot` scene, for load-balancing studies: a plain diffuse room whose geometry and
// shading cost sit almost entirely in the top-left corner of the image, where a dense cluster
// of finely tessellated spheres (diffuse, glass and mirror) floats. A static equal split of
// the image gives one PE nearly all the work; demand-driven and hot-spots-first schedules fix it.
#include <array>
#include <numbers>
#include <string>

#include "tools/scenegen/random.h"
#include "tools/scenegen/scene_registry.h"

namespace pr::scenegen {
namespace {

// Cluster: kCols x kRows x kLayers spheres on a jittered grid, centred where the camera's
// view (eye (0, 3, 12), yfov 50 degrees, square) has its top-left quarter at z = -4:
// x in [-7.5, -3.7], y in [6.7, 10.5].
constexpr int kCols = 8, kRows = 5, kLayers = 2;
constexpr float kSpacing = 0.5f;
constexpr glm::vec3 kClusterCenter{-5.4f, 8.4f, -4.0f};

}  // namespace

void buildHotspot(GltfBuilder& b, const SceneParams& params) {
  const int wall = b.addMaterial({.name = "wall", .baseColor = {0.7f, 0.7f, 0.7f, 1.0f}, .specular = 0.0f});
  b.addMeshNode("floor", b.addMesh("floor", makeQuad({-10, 0, 12}, {20, 0, 0}, {0, 0, -18}), wall));
  b.addMeshNode("back wall", b.addMesh("back wall", makeQuad({-10, 0, -6}, {20, 0, 0}, {0, 12, 0}), wall));

  // Sphere materials: four diffuse colours, glass and mirror; each sphere picks one from the
  // seeded stream (60% diffuse, 20% glass, 20% mirror).
  const std::array<glm::vec4, 4> colours = {glm::vec4(0.8f, 0.2f, 0.2f, 1), glm::vec4(0.2f, 0.7f, 0.3f, 1),
                                            glm::vec4(0.2f, 0.3f, 0.8f, 1), glm::vec4(0.8f, 0.7f, 0.2f, 1)};
  std::array<int, 6> materials{};
  for (int i = 0; i < 4; ++i)
    materials[i] = b.addMaterial({.name = "diffuse " + std::to_string(i), .baseColor = colours[i], .specular = 0.0f});
  materials[4] = b.addMaterial(
      {.name = "glass", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 1.5f});
  materials[5] = b.addMaterial({.name = "mirror", .baseColor = glm::vec4(1.0f), .metallic = 1.0f, .roughness = 0.0f});

  // One unit-sphere tessellation; one mesh per material shares it; nodes place and scale it.
  std::array<int, 6> meshes;
  meshes.fill(-1);
  int geometry = -1;
  auto meshFor = [&](int choice) {
    if (meshes[choice] >= 0) return meshes[choice];
    const std::string name = "sphere " + b.model().materials[materials[choice]].name;
    if (geometry < 0) {
      geometry = b.addMesh(name, makeUvSphere(1.0f, params.size, params.size / 2), materials[choice]);
      meshes[choice] = geometry;
    } else {
      meshes[choice] = b.addMeshSharingGeometry(name, geometry, materials[choice]);
    }
    return meshes[choice];
  };

  SplitMix64 rng(params.seed);
  int index = 0;
  for (int layer = 0; layer < kLayers; ++layer)
    for (int row = 0; row < kRows; ++row)
      for (int col = 0; col < kCols; ++col, ++index) {
        const glm::vec3 cell((col - (kCols - 1) / 2.0f) * kSpacing, (row - (kRows - 1) / 2.0f) * kSpacing,
                             (layer - (kLayers - 1) / 2.0f) * kSpacing);
        // Jitter up to 0.04 per axis and radius in [0.17, 0.21]: spheres never overlap, since
        // 2 * (0.21 + 0.04) = 0.5 = the grid spacing.
        const glm::vec3 jitter(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f);
        const float radius = 0.17f + 0.04f * rng.uniform();
        const uint32_t pick = rng.below(10);
        const int choice = pick < 6 ? static_cast<int>(pick % 4) : (pick < 8 ? 4 : 5);
        b.addMeshNode("sphere " + std::to_string(index), meshFor(choice),
                      {.translation = kClusterCenter + cell + 0.08f * jitter, .scale = radius});
      }

  // Lights: a point light over the room's centre and a small downward-facing area light
  // (0.8 x 0.8, radiance 20) to the right of the cluster.
  b.addPointLight("point light", glm::vec3(1.0f), 60.0f, {0.0f, 9.0f, 6.0f});
  const int emitter = b.addMaterial({.name = "light",
                                     .baseColor = {0.0f, 0.0f, 0.0f, 1.0f},
                                     .emissive = glm::vec3(1.0f),
                                     .emissiveStrength = 20.0f,
                                     .specular = 0.0f});
  b.addMeshNode("area light", b.addMesh("area light", makeQuad({2.6f, 9.0f, -0.6f}, {0, 0, -0.8f}, {0.8f, 0, 0}), emitter));

  b.addPerspectiveCamera("camera", 50.0f * std::numbers::pi_v<float> / 180.0f, 1.0f, 0.1f, 100.0f, {0.0f, 3.0f, 12.0f},
                         {0.0f, 3.0f, -6.0f});
}

}  // namespace pr::scenegen
