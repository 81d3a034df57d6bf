// In-memory glTF 2.0 model for the scene generator and its serialisation through tinygltf's
// writer (see gltf_builder.h). All numbers come from the scene builders' float arithmetic and
// tinygltf writes JSON keys in sorted order, so the output bytes are deterministic.
#include "tools/scenegen/gltf_builder.h"

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>
#include <unistd.h>

#include "common/util/error.h"

namespace pr::scenegen {
namespace {

namespace fs = std::filesystem;

// The double nearest the float's shortest decimal form, so the JSON says 0.73, not the
// float's exact binary value 0.7300000190734863; reading it back as float gives the same float.
double clean(float f) {
  char text[32];
  auto result = std::to_chars(text, text + sizeof text - 1, f);
  *result.ptr = '\0';
  return std::strtod(text, nullptr);
}

std::vector<double> toDoubles(glm::vec3 v) { return {clean(v.x), clean(v.y), clean(v.z)}; }
std::vector<double> toDoubles(glm::vec4 v) { return {clean(v.x), clean(v.y), clean(v.z), clean(v.w)}; }

}  // namespace

glm::quat lookAtRotation(glm::vec3 eye, glm::vec3 target, glm::vec3 up) {
  // Camera basis: -z toward the target, x = forward x up; the quaternion of that matrix.
  const glm::vec3 back = glm::normalize(eye - target);
  const glm::vec3 right = glm::normalize(glm::cross(up, back));
  const glm::vec3 trueUp = glm::cross(back, right);
  return glm::normalize(glm::quat_cast(glm::mat3(right, trueUp, back)));
}

GltfBuilder::GltfBuilder(const std::string& generator) {
  model_.asset.version = "2.0";
  model_.asset.generator = generator;
  model_.buffers.emplace_back();
  model_.scenes.emplace_back();
  model_.scenes[0].name = "scene";
  model_.defaultScene = 0;
}

void GltfBuilder::useExtension(const std::string& name) {
  for (const auto& used : model_.extensionsUsed)
    if (used == name) return;
  model_.extensionsUsed.push_back(name);
}

namespace {
tinygltf::Value::Array toValues(glm::vec3 v) {
  return {tinygltf::Value(clean(v.x)), tinygltf::Value(clean(v.y)), tinygltf::Value(clean(v.z))};
}
}  // namespace

int GltfBuilder::addMaterial(const MaterialDesc& desc) {
  tinygltf::Material m;
  m.name = desc.name;
  m.pbrMetallicRoughness.baseColorFactor = toDoubles(desc.baseColor);
  m.pbrMetallicRoughness.metallicFactor = clean(desc.metallic);
  m.pbrMetallicRoughness.roughnessFactor = clean(desc.roughness);
  m.emissiveFactor = toDoubles(desc.emissive);
  if (desc.emissiveStrength > 0.0f) {
    tinygltf::Value::Object ext{{"emissiveStrength", tinygltf::Value(clean(desc.emissiveStrength))}};
    m.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(ext);
    useExtension("KHR_materials_emissive_strength");
  }
  if (desc.transmission > 0.0f) {
    tinygltf::Value::Object tr{{"transmissionFactor", tinygltf::Value(clean(desc.transmission))}};
    m.extensions["KHR_materials_transmission"] = tinygltf::Value(tr);
    tinygltf::Value::Object ior{{"ior", tinygltf::Value(clean(desc.ior))}};
    m.extensions["KHR_materials_ior"] = tinygltf::Value(ior);
    useExtension("KHR_materials_transmission");
    useExtension("KHR_materials_ior");
  }
  if (desc.attenuationDistance > 0.0f) {
    tinygltf::Value::Object volume{{"attenuationDistance", tinygltf::Value(clean(desc.attenuationDistance))},
                                   {"attenuationColor", tinygltf::Value(toValues(desc.attenuationColor))},
                                   {"thicknessFactor", tinygltf::Value(clean(desc.thickness))}};
    m.extensions["KHR_materials_volume"] = tinygltf::Value(volume);
    useExtension("KHR_materials_volume");
  }
  if (desc.specular != 1.0f) {
    tinygltf::Value::Object specular{{"specularFactor", tinygltf::Value(clean(desc.specular))}};
    m.extensions["KHR_materials_specular"] = tinygltf::Value(specular);
    useExtension("KHR_materials_specular");
  }
  m.doubleSided = desc.doubleSided;
  model_.materials.push_back(std::move(m));
  return static_cast<int>(model_.materials.size()) - 1;
}

int GltfBuilder::addBufferView(const void* data, size_t bytes, int target) {
  auto& buffer = model_.buffers[0].data;
  // Every view starts on a 4-byte boundary, as float accessors require (glTF 3.6.2.4).
  buffer.resize((buffer.size() + 3) & ~size_t{3}, 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + bytes);
  model_.bufferViews.push_back(view);
  return static_cast<int>(model_.bufferViews.size()) - 1;
}

int GltfBuilder::addMesh(const std::string& name, const MeshData& mesh, int material) {
  PR_CHECK(!mesh.positions.empty() && mesh.positions.size() == mesh.normals.size() && mesh.indices.size() % 3 == 0,
           "malformed generated mesh " + name);
  static_assert(sizeof(glm::vec3) == 12);
  const size_t vertices = mesh.positions.size();

  tinygltf::Accessor pos;
  pos.bufferView = addBufferView(mesh.positions.data(), vertices * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
  pos.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  pos.count = vertices;
  pos.type = TINYGLTF_TYPE_VEC3;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (glm::vec3 p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  pos.minValues = toDoubles(lo);
  pos.maxValues = toDoubles(hi);

  tinygltf::Accessor nrm;
  nrm.bufferView = addBufferView(mesh.normals.data(), vertices * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
  nrm.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  nrm.count = vertices;
  nrm.type = TINYGLTF_TYPE_VEC3;

  tinygltf::Accessor idx;
  idx.type = TINYGLTF_TYPE_SCALAR;
  idx.count = mesh.indices.size();
  if (vertices <= std::numeric_limits<uint16_t>::max()) {
    std::vector<uint16_t> small(mesh.indices.begin(), mesh.indices.end());
    idx.bufferView = addBufferView(small.data(), small.size() * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  } else {
    idx.bufferView =
        addBufferView(mesh.indices.data(), mesh.indices.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  }

  const int first = static_cast<int>(model_.accessors.size());
  model_.accessors.push_back(std::move(pos));
  model_.accessors.push_back(std::move(nrm));
  model_.accessors.push_back(std::move(idx));

  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = first;
  prim.attributes["NORMAL"] = first + 1;
  prim.indices = first + 2;
  prim.material = material;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh m;
  m.name = name;
  m.primitives.push_back(std::move(prim));
  model_.meshes.push_back(std::move(m));
  return static_cast<int>(model_.meshes.size()) - 1;
}

int GltfBuilder::addMeshSharingGeometry(const std::string& name, int geometryMesh, int material) {
  PR_CHECK(geometryMesh >= 0 && geometryMesh < static_cast<int>(model_.meshes.size()), "no such mesh");
  tinygltf::Mesh m;
  m.name = name;
  m.primitives.push_back(model_.meshes[geometryMesh].primitives.at(0));
  m.primitives[0].material = material;
  model_.meshes.push_back(std::move(m));
  return static_cast<int>(model_.meshes.size()) - 1;
}

int GltfBuilder::addNode(tinygltf::Node node) {
  model_.nodes.push_back(std::move(node));
  const int index = static_cast<int>(model_.nodes.size()) - 1;
  model_.scenes[0].nodes.push_back(index);
  return index;
}

int GltfBuilder::addMeshNode(const std::string& name, int mesh, const Placement& placement) {
  tinygltf::Node node;
  node.name = name;
  node.mesh = mesh;
  if (placement.translation != glm::vec3(0.0f)) node.translation = toDoubles(placement.translation);
  const glm::quat& q = placement.rotation;
  if (q != glm::quat(1.0f, 0.0f, 0.0f, 0.0f)) node.rotation = {clean(q.x), clean(q.y), clean(q.z), clean(q.w)};
  if (placement.scale != 1.0f) node.scale = toDoubles(glm::vec3(placement.scale));
  // Each node instance counts: a renderer flattens instances into world-space triangles.
  for (const auto& prim : model_.meshes.at(mesh).primitives) triangles_ += model_.accessors[prim.indices].count / 3;
  return addNode(std::move(node));
}

int GltfBuilder::addPerspectiveCamera(const std::string& name, float yfovRadians, float aspectRatio, float znear,
                                      float zfar, glm::vec3 eye, glm::vec3 target) {
  tinygltf::Camera camera;
  camera.name = name;
  camera.type = "perspective";
  camera.perspective.yfov = clean(yfovRadians);
  camera.perspective.aspectRatio = clean(aspectRatio);
  camera.perspective.znear = clean(znear);
  camera.perspective.zfar = clean(zfar);
  model_.cameras.push_back(std::move(camera));

  tinygltf::Node node;
  node.name = name;
  node.camera = static_cast<int>(model_.cameras.size()) - 1;
  node.translation = toDoubles(eye);
  const glm::quat q = lookAtRotation(eye, target);
  if (q != glm::quat(1.0f, 0.0f, 0.0f, 0.0f)) node.rotation = {clean(q.x), clean(q.y), clean(q.z), clean(q.w)};
  return addNode(std::move(node));
}

int GltfBuilder::addPointLight(const std::string& name, glm::vec3 color, float intensityCandela, glm::vec3 position) {
  tinygltf::Light light;
  light.name = name;
  light.type = "point";
  light.color = toDoubles(color);
  light.intensity = clean(intensityCandela);
  model_.lights.push_back(std::move(light));

  tinygltf::Node node;
  node.name = name;
  node.translation = toDoubles(position);
  tinygltf::Value::Object ext{{"light", tinygltf::Value(static_cast<int>(model_.lights.size()) - 1)}};
  node.extensions["KHR_lights_punctual"] = tinygltf::Value(ext);
  return addNode(std::move(node));
}

std::string GltfBuilder::serialize(bool binary) const {
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  // The stream writer embeds buffer 0 in the GLB's BIN chunk or as a base64 data URI.
  PR_CHECK(writer.WriteGltfSceneToStream(&model_, out, /*prettyPrint=*/true, binary), "tinygltf could not serialise");
  return out.str();
}


}  // namespace pr::scenegen
