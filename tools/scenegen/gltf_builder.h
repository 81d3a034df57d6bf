// Builds a glTF 2.0 model in memory (tinygltf) from generated meshes, materials, cameras and
// lights, and writes it as .gltf (JSON with the buffer embedded as base64) or .glb (binary).
// The scene builders (cornell.cpp, landscape.cpp, hotspot.cpp) call it; cmd_generate writes.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "tools/scenegen/mesh_gen.h"

namespace pr::scenegen {

// A metallic-roughness material with the KHR extensions the bundled scenes use. Zero
// emissiveStrength or transmission leaves that extension out; ior 1.5 is glTF's default
// and is written only when transmission is on.
struct MaterialDesc {
  std::string name;
  glm::vec4 baseColor{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  glm::vec3 emissive{0.0f};      // emissiveFactor, each channel in [0, 1]
  float emissiveStrength = 0.0f;  // KHR_materials_emissive_strength (> 1 for bright lights)
  float transmission = 0.0f;      // KHR_materials_transmission
  float ior = 1.5f;               // KHR_materials_ior
  bool doubleSided = false;
  // KHR_materials_volume, written when attenuationDistance > 0 (with transmission).
  float attenuationDistance = 0.0f;
  glm::vec3 attenuationColor{1.0f};
  float thickness = 0.0f;
  // KHR_materials_specular's specularFactor, written when not 1: 0 makes a dielectric purely
  // Lambertian (no Fresnel layer), which is how the glTF spec spells a diffuse-only surface.
  float specular = 1.0f;
};

// Node placement: translation, rotation (unit quaternion), uniform scale.
struct Placement {
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // glm order: w, x, y, z
  float scale = 1.0f;
};

// Rotation that turns a glTF camera (looking down its local -z, +y up) from `eye` to `target`.
glm::quat lookAtRotation(glm::vec3 eye, glm::vec3 target, glm::vec3 up = glm::vec3(0.0f, 1.0f, 0.0f));

class GltfBuilder {
 public:
  explicit GltfBuilder(const std::string& generator);

  int addMaterial(const MaterialDesc& material);
  // A mesh with one triangle primitive; its accessors (POSITION with min/max, NORMAL,
  // indices as uint16 when possible) go into the single buffer.
  int addMesh(const std::string& name, const MeshData& mesh, int material);
  // A mesh reusing `geometryMesh`'s accessors with another material: instanced spheres.
  int addMeshSharingGeometry(const std::string& name, int geometryMesh, int material);
  // A node in the default scene; returns its index.
  int addMeshNode(const std::string& name, int mesh, const Placement& placement = {});
  int addPerspectiveCamera(const std::string& name, float yfovRadians, float aspectRatio, float znear,
                           float zfar, glm::vec3 eye, glm::vec3 target);
  // KHR_lights_punctual point light, intensity in candela.
  int addPointLight(const std::string& name, glm::vec3 color, float intensityCandela, glm::vec3 position);

  size_t triangleCount() const { return triangles_; }
  const tinygltf::Model& model() const { return model_; }

  // Serialises to bytes: binary glTF when `binary`, else JSON with an embedded data URI.
  std::string serialize(bool binary) const;

 private:
  int addBufferView(const void* data, size_t bytes, int target);
  int addNode(tinygltf::Node node);
  void useExtension(const std::string& name);

  tinygltf::Model model_;
  size_t triangles_ = 0;
};

}  // namespace pr::scenegen
