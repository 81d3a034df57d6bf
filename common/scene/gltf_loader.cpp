// glTF 2.0 into the render-ready Scene (runs once, before any PE starts): parses with
// tinygltf, checks required extensions, walks the default scene's node hierarchy and
// flattens every drawn mesh primitive, light and camera into world space.
// Geometry rules: glTF 2.0 spec 3.5 (transforms), 3.7.2 (primitive modes, winding).
#include "common/scene/gltf_loader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <span>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "common/scene/gltf_accessor.h"
#include "common/scene/gltf_context.h"
#include "common/scene/gltf_material.h"
#include "common/scene/tangent_frame.h"
#include "common/util/limits.h"

namespace pr::scene {

namespace {

using gltf::Context;
using gltf::describe;

// Extensions whose content parrender honours; only these may appear in extensionsRequired.
constexpr std::array<const char*, 11> kSupportedExtensions = {
    "KHR_lights_punctual",      "KHR_materials_emissive_strength", "KHR_materials_transmission",
    "KHR_materials_ior",        "KHR_materials_volume",            "KHR_materials_anisotropy",
    "KHR_materials_specular",   "KHR_materials_clearcoat",         "KHR_materials_sheen",
    "KHR_materials_variants",   "KHR_texture_transform"};

bool supported(const std::string& name) {
  return std::any_of(kSupportedExtensions.begin(), kSupportedExtensions.end(),
                     [&](const char* s) { return name == s; });
}

std::string supportedList() {
  std::string out;
  for (const char* s : kSupportedExtensions) out += (out.empty() ? "" : ", ") + std::string(s);
  return out;
}

// Unit vector, or `fallback` for a zero / non-finite one (degenerate triangle, zero scale).
glm::vec3 safeNormalize(glm::vec3 v, glm::vec3 fallback) {
  float len = glm::length(v);
  return len > 0.0f && std::isfinite(len) ? v / len : fallback;
}

// Parses the file with tinygltf; anything it rejects is one InputError naming the file.
tinygltf::Model parse(const std::filesystem::path& path, std::vector<std::string>& tinyWarnings) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(file + ": cannot read the file (" +
                     (std::filesystem::exists(path, ec) ? "not a regular file" : "no such file") + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file + ": cannot read the file (permission denied or unreadable)");
  // A .glb starts with the magic "glTF" (spec 4.4.2); anything else is parsed as JSON.
  char magic[4] = {};
  const bool binary = in.read(magic, 4) && std::string_view(magic, 4) == "glTF";

  tinygltf::TinyGLTF parser;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = binary ? parser.LoadBinaryFromFile(&model, &err, &warn, file)
                   : parser.LoadASCIIFromFile(&model, &err, &warn, file);
  if (!ok) {
    // tinygltf reports several lines; the first names the actual problem.
    std::string reason = err.empty() ? "unknown parse error" : err.substr(0, err.find('\n'));
    const std::string kNotFound = "File not found : ";
    if (reason.rfind(kNotFound, 0) == 0) {
      throw InputError(file + ": buffer file '" + reason.substr(kNotFound.size()) +
                       "' is missing or unreadable (looked next to the glTF file)");
    }
    throw InputError(file + ": not a valid glTF " + (binary ? "binary (.glb)" : "file") + ": " + reason);
  }
  for (size_t start = 0; start < warn.size();) {
    size_t end = warn.find('\n', start);
    if (end == std::string::npos) end = warn.size();
    if (end > start) tinyWarnings.push_back(warn.substr(start, end - start));
    start = end + 1;
  }
  return model;
}

// Local transform of a node: its matrix, or T * R * S (spec 3.5.3).
glm::dmat4 localTransform(const Context& ctx, const tinygltf::Node& node, int index) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());
  if (!node.matrix.empty()) ctx.fail(describe("node", index, node.name) + ": matrix must have 16 numbers");
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    // glTF stores (x, y, z, w); glm's constructor takes (w, x, y, z).
    glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    m = m * glm::mat4_cast(glm::normalize(q));
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// Whether an emissive texture has any non-black texel under a triangle's UVs. Scans the
// texel rectangle bounding the (transformed) UV triangle, grown by one texel for bilinear
// bleeding: conservative, so a triangle that emits anywhere is never dropped. Footprints over
// kMaxTexels (tiled or huge) are assumed to emit rather than scanned.
bool emissiveTexelUnder(const Texture& texture, const TextureRef& ref, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  constexpr double kMaxTexels = 1 << 18;
  glm::vec2 ta = ref.transformUv(a), tb = ref.transformUv(b), tc = ref.transformUv(c);
  glm::vec2 lo = glm::min(ta, glm::min(tb, tc)), hi = glm::max(ta, glm::max(tb, tc));
  double x0 = std::floor(double(lo.x) * texture.width) - 1, x1 = std::floor(double(hi.x) * texture.width) + 1;
  double y0 = std::floor(double(lo.y) * texture.height) - 1, y1 = std::floor(double(hi.y) * texture.height) + 1;
  if (!((x1 - x0 + 1) * (y1 - y0 + 1) <= kMaxTexels)) return true;  // also catches NaN
  auto wrap = [](int i, int n, Wrap mode) {  // the same mapping as Texture::sample
    if (mode == Wrap::ClampToEdge) return std::clamp(i, 0, n - 1);
    if (mode == Wrap::Repeat) return ((i % n) + n) % n;
    int period = 2 * n, m = ((i % period) + period) % period;
    return m < n ? m : period - 1 - m;
  };
  for (int y = int(y0); y <= int(y1); ++y) {
    const size_t row = size_t(wrap(y, texture.height, texture.sampler.wrapT)) * size_t(texture.width);
    for (int x = int(x0); x <= int(x1); ++x) {
      const uint8_t* p = &texture.rgba8[(row + size_t(wrap(x, texture.width, texture.sampler.wrapS))) * 4];
      if (p[0] | p[1] | p[2]) return true;
    }
  }
  return false;
}

class Flattener {
 public:
  explicit Flattener(Context& ctx) : ctx_(ctx), accessors_(ctx) {}

  void visit(int index, const glm::dmat4& parent, int depth) {
    const auto& model = ctx_.model;
    if (index < 0 || size_t(index) >= model.nodes.size()) {
      ctx_.fail("node " + std::to_string(index) + " is out of range (the file has " + std::to_string(model.nodes.size()) +
                " nodes)");
    }
    if (onPath_.empty()) onPath_.assign(model.nodes.size(), false);
    if (onPath_[size_t(index)]) ctx_.fail(describe("node", index, model.nodes[size_t(index)].name) + " is its own ancestor (cycle)");
    onPath_[size_t(index)] = true;
    // A legal hierarchy is a forest; this bound only keeps a pathological file off the stack.
    constexpr int kMaxDepth = 1000;
    if (depth > kMaxDepth) ctx_.fail(describe("node", index, model.nodes[size_t(index)].name) + ": hierarchy deeper than 1000 levels");
    const tinygltf::Node& node = model.nodes[size_t(index)];
    const glm::dmat4 world = parent * localTransform(ctx_, node, index);

    if (node.skin >= 0) ctx_.warn(describe("node", index, node.name) + ": skin ignored (drawn in its bind pose)");
    if (node.mesh >= 0) addMesh(index, node, world);
    if (node.camera >= 0) addCamera(index, node, world);
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end() && it->second.Has("light")) {
      addLight(index, node, it->second.Get("light").GetNumberAsInt(), world);
    }
    for (int child : node.children) visit(child, world, depth + 1);
    onPath_[size_t(index)] = false;
  }

  // Emissive triangles become area lights; vertex colours are dropped when no primitive had any.
  void finish() {
    Scene& s = ctx_.scene;
    if (!anyColors_) s.colors.clear();
    if (!anyTangents_) s.tangents.clear();
    for (uint32_t t = 0; t < s.triangles.size(); ++t) {
      const Triangle& tri = s.triangles[t];
      const Material& material = s.materials[tri.material];
      if (!material.isEmissive()) continue;
      if (material.emissiveTexture.present() &&
          !emissiveTexelUnder(s.textures[size_t(material.emissiveTexture.texture)], material.emissiveTexture,
                              s.uvs[tri.v[0]], s.uvs[tri.v[1]], s.uvs[tri.v[2]])) {
        continue;  // emission = factor * texture, and the texture is black under this triangle
      }
      glm::vec3 e1 = s.positions[tri.v[1]] - s.positions[tri.v[0]];
      glm::vec3 e2 = s.positions[tri.v[2]] - s.positions[tri.v[0]];
      float area = 0.5f * glm::length(glm::cross(e1, e2));
      if (area > 0.0f) s.areaLights.push_back({t, area});  // a zero-area emitter emits nothing
    }
    for (const glm::vec3& p : s.positions) s.bounds.extend(p);
  }

 private:
  void addMesh(int nodeIndex, const tinygltf::Node& node, const glm::dmat4& world) {
    const auto& model = ctx_.model;
    if (size_t(node.mesh) >= model.meshes.size()) {
      ctx_.fail(describe("node", nodeIndex, node.name) + ": mesh " + std::to_string(node.mesh) +
                " is out of range (the file has " + std::to_string(model.meshes.size()) + " meshes)");
    }
    const tinygltf::Mesh& mesh = model.meshes[size_t(node.mesh)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) addPrimitive(nodeIndex, node, node.mesh, mesh, int(p), world);
  }

  // Triangle list of a primitive, as vertex indices local to the primitive (spec 3.7.2.1).
  std::vector<uint32_t> triangleList(const tinygltf::Primitive& prim, size_t vertexCount, const std::string& where) {
    std::vector<uint32_t> seq;
    // Triangle indices are 32 bits too: checked on the declared count, before reading indices.
    const uint64_t declared = prim.indices >= 0 && size_t(prim.indices) < ctx_.model.accessors.size()
                                  ? uint64_t(ctx_.model.accessors[size_t(prim.indices)].count)
                                  : uint64_t(vertexCount);
    const uint64_t triangles = prim.mode == TINYGLTF_MODE_TRIANGLES ? declared / 3 : (declared >= 3 ? declared - 2 : 0);
    const std::string problem = countLimitProblem(where, "triangles in the scene",
                                                  uint64_t(ctx_.scene.triangles.size()) + triangles, kMaxTriangles,
                                                  "triangle indices are 32 bits");
    if (!problem.empty()) ctx_.fail(problem);
    if (prim.indices >= 0) {
      seq = accessors_.indices(prim.indices, where + " indices");
      for (uint32_t i : seq) {
        if (i >= vertexCount) {
          ctx_.fail(where + ": index " + std::to_string(i) + " is out of range (POSITION has " +
                    std::to_string(vertexCount) + " vertices)");
        }
      }
    } else {
      seq.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) seq[i] = uint32_t(i);
    }
    std::vector<uint32_t> tris;
    const size_t n = seq.size();
    switch (prim.mode) {
      case TINYGLTF_MODE_TRIANGLES:
        if (n % 3 != 0) ctx_.warn(where + ": " + std::to_string(n) + " vertices is not a multiple of 3; the last " + std::to_string(n % 3) + " ignored");
        tris.assign(seq.begin(), seq.begin() + ptrdiff_t(n - n % 3));
        break;
      case TINYGLTF_MODE_TRIANGLE_STRIP:
        // Triangle i = {v_i, v_{i+1+i%2}, v_{i+2-i%2}}: every other one reversed to keep winding.
        for (size_t i = 0; i + 2 < n; ++i) {
          tris.insert(tris.end(), {seq[i], seq[i + 1 + i % 2], seq[i + 2 - i % 2]});
        }
        break;
      case TINYGLTF_MODE_TRIANGLE_FAN:
        // Triangle i = {v_{i+1}, v_{i+2}, v_0}.
        for (size_t i = 0; i + 2 < n; ++i) tris.insert(tris.end(), {seq[i + 1], seq[i + 2], seq[0]});
        break;
      default:
        break;
    }
    return tris;
  }

  // The material the selected variant maps this primitive to, or -1 (no variant, no mapping).
  int variantMaterial(const tinygltf::Primitive& prim, const std::string& where) {
    if (ctx_.variant < 0) return -1;
    auto it = prim.extensions.find("KHR_materials_variants");
    if (it == prim.extensions.end() || !it->second.Has("mappings") || !it->second.Get("mappings").IsArray()) return -1;
    const tinygltf::Value& mappings = it->second.Get("mappings");
    for (size_t i = 0; i < mappings.ArrayLen(); ++i) {
      const tinygltf::Value& m = mappings.Get(int(i));
      if (!m.Has("variants") || !m.Get("variants").IsArray() || !m.Has("material") || !m.Get("material").IsNumber()) continue;
      const tinygltf::Value& vs = m.Get("variants");
      for (size_t k = 0; k < vs.ArrayLen(); ++k) {
        if (!vs.Get(int(k)).IsNumber() || vs.Get(int(k)).GetNumberAsInt() != ctx_.variant) continue;
        const int material = m.Get("material").GetNumberAsInt();
        if (material < 0 || size_t(material) + 1 >= ctx_.scene.materials.size()) {
          ctx_.fail(where + ": KHR_materials_variants maps to material " + std::to_string(material) +
                    ", which is out of range (the file has " + std::to_string(ctx_.scene.materials.size() - 1) +
                    " materials)");
        }
        return material;
      }
    }
    return -1;
  }

  void addPrimitive(int nodeIndex, const tinygltf::Node& node, int meshIndex, const tinygltf::Mesh& mesh, int primIndex,
                    const glm::dmat4& world) {
    const tinygltf::Primitive& prim = mesh.primitives[size_t(primIndex)];
    const std::string where = describe("mesh", meshIndex, mesh.name) + " primitive " + std::to_string(primIndex);
    if (prim.mode < TINYGLTF_MODE_TRIANGLES || prim.mode > TINYGLTF_MODE_TRIANGLE_FAN) {
      static const char* kModeNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
      std::string mode = prim.mode >= 0 && prim.mode < 4 ? kModeNames[prim.mode] : "mode " + std::to_string(prim.mode);
      ctx_.warn(where + ": " + mode + " skipped (only triangles are drawn)");
      return;
    }
    if (!prim.targets.empty()) ctx_.warn(where + ": morph targets ignored (base shape drawn)");
    auto attribute = [&](const char* name) {
      auto it = prim.attributes.find(name);
      return it == prim.attributes.end() ? -1 : it->second;
    };
    const int posIndex = attribute("POSITION");
    if (posIndex < 0) ctx_.fail(where + ": has no POSITION attribute");
    // Vertex indices are 32 bits: checked on the declared count, before any data is read.
    if (size_t(posIndex) < ctx_.model.accessors.size()) {
      const std::string problem =
          countLimitProblem(where + " POSITION", "vertices in the scene",
                            uint64_t(ctx_.scene.positions.size()) + uint64_t(ctx_.model.accessors[size_t(posIndex)].count),
                            kMaxVertices, "vertex indices are 32 bits");
      if (!problem.empty()) ctx_.fail(problem);
    }
    const gltf::FloatAccessor& pos = accessors_.floats(posIndex, where + " POSITION");
    if (pos.components != 3) ctx_.fail(where + " POSITION: accessor " + std::to_string(posIndex) + " must be VEC3");
    const size_t count = pos.count;
    auto optional = [&](const char* name, int minComponents, int maxComponents) -> const gltf::FloatAccessor* {
      int index = attribute(name);
      if (index < 0) return nullptr;
      const gltf::FloatAccessor& a = accessors_.floats(index, where + " " + name);
      if (a.components < minComponents || a.components > maxComponents) {
        ctx_.fail(where + " " + name + ": accessor " + std::to_string(index) + " has " + std::to_string(a.components) +
                  " components, expected " + std::to_string(minComponents) +
                  (maxComponents != minComponents ? " or " + std::to_string(maxComponents) : ""));
      }
      if (a.count != count) {
        ctx_.fail(where + " " + name + ": accessor " + std::to_string(index) + " has " + std::to_string(a.count) +
                  " elements but POSITION has " + std::to_string(count));
      }
      return &a;
    };
    const gltf::FloatAccessor* normal = optional("NORMAL", 3, 3);
    const gltf::FloatAccessor* uv = optional("TEXCOORD_0", 2, 2);
    const gltf::FloatAccessor* color = optional("COLOR_0", 3, 4);
    const gltf::FloatAccessor* tangent = optional("TANGENT", 4, 4);

    uint32_t material = uint32_t(ctx_.scene.materials.size() - 1);  // the default material
    if (prim.material >= 0) {
      if (size_t(prim.material) + 1 >= ctx_.scene.materials.size()) {
        ctx_.fail(where + ": material " + std::to_string(prim.material) + " is out of range (the file has " +
                  std::to_string(ctx_.scene.materials.size() - 1) + " materials)");
      }
      material = uint32_t(prim.material);
    }
    if (const int mapped = variantMaterial(prim, where); mapped >= 0) material = uint32_t(mapped);

    std::vector<uint32_t> local = triangleList(prim, count, where);
    if (local.empty()) return;

    // World-space vertices. A mirroring transform (det < 0) reverses the apparent winding, so
    // triangles are re-wound below; normals transform by the inverse transpose (spec 3.5.2).
    Scene& s = ctx_.scene;
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
    const glm::mat3 normalMatrix(glm::transpose(glm::inverse(glm::dmat3(world))));
    const uint32_t base = uint32_t(s.positions.size());
    PR_CHECK(s.positions.size() + count <= kMaxVertices, "scene exceeds kMaxVertices (checked above)");
    for (size_t i = 0; i < count; ++i) {
      const float* p = pos.element(i);
      s.positions.push_back(glm::vec3(world * glm::dvec4(p[0], p[1], p[2], 1.0)));
      s.uvs.push_back(uv ? glm::vec2(uv->element(i)[0], uv->element(i)[1]) : glm::vec2(0.0f));
      if (color) {
        const float* c = color->element(i);
        s.colors.push_back(glm::vec4(c[0], c[1], c[2], color->components == 4 ? c[3] : 1.0f));
        anyColors_ = true;
      } else {
        s.colors.push_back(glm::vec4(1.0f));
      }
    }
    const uint32_t firstTriangle = uint32_t(s.triangles.size());
    for (size_t t = 0; t + 2 < local.size(); t += 3) {
      Triangle tri{{base + local[t], base + local[t + 1], base + local[t + 2]}, material};
      if (mirrored) std::swap(tri.v[1], tri.v[2]);
      s.triangles.push_back(tri);
    }

    // Normals: authored ones transformed; generated ones area-weighted (the unnormalised cross
    // product is twice the area times the unit normal) from the re-wound world triangles.
    std::vector<glm::vec3> generated;
    auto generate = [&] {
      generated.assign(count, glm::vec3(0.0f));
      for (uint32_t t = firstTriangle; t < s.triangles.size(); ++t) {
        const Triangle& tri = s.triangles[t];
        glm::vec3 n = glm::cross(s.positions[tri.v[1]] - s.positions[tri.v[0]], s.positions[tri.v[2]] - s.positions[tri.v[0]]);
        for (uint32_t v : tri.v) generated[v - base] += n;
      }
    };
    if (!normal) generate();
    for (size_t i = 0; i < count; ++i) {
      glm::vec3 n;
      if (normal) {
        const float* a = normal->element(i);
        n = normalMatrix * glm::vec3(a[0], a[1], a[2]);
        if (!(glm::length(n) > 0.0f)) {  // zero authored normal: use the surface's own
          if (generated.empty()) generate();
          n = generated[i];
        }
      } else {
        n = generated[i];
      }
      // A vertex only on zero-area triangles has no defined normal; +Y is as good as any.
      s.normals.push_back(safeNormalize(n, glm::vec3(0.0f, 1.0f, 0.0f)));
    }

    // Tangents, only where a normal map needs them: the file's (xyz by the node transform; a
    // mirroring transform flips the bitangent, so w too), else generated from the UVs.
    const Material& mat = s.materials[material];
    const bool normalMapped = (mat.normalTexture.present() || mat.clearcoatNormalTexture.present()) && uv;
    s.tangents.resize(s.positions.size(), glm::vec4(0.0f));
    if (normalMapped) {
      anyTangents_ = true;
      const std::span<glm::vec4> out(s.tangents.data() + base, count);
      if (tangent) {
        const glm::mat3 linear{glm::dmat3(world)};
        for (size_t i = 0; i < count; ++i) {
          const float* a = tangent->element(i);
          const glm::vec3 n = s.normals[base + i];
          glm::vec3 t = linear * glm::vec3(a[0], a[1], a[2]);
          t = safeNormalize(t - glm::dot(t, n) * n, glm::vec3(0.0f));
          out[i] = glm::vec4(t, (a[3] < 0.0f) != mirrored ? -1.0f : 1.0f);
        }
      } else {
        generateTangents(s, base, firstTriangle, out);
      }
    }

    Object object;
    object.name = (node.name.empty() ? "node" + std::to_string(nodeIndex) : node.name) + "/" +
                  (mesh.name.empty() ? "mesh" + std::to_string(meshIndex) : mesh.name) + "#" + std::to_string(primIndex);
    object.node = nodeIndex;
    object.mesh = meshIndex;
    object.primitive = primIndex;
    object.firstTriangle = firstTriangle;
    object.triangleCount = uint32_t(s.triangles.size()) - firstTriangle;
    for (size_t i = base; i < s.positions.size(); ++i) object.bounds.extend(s.positions[i]);
    s.objects.push_back(std::move(object));
  }

  void addCamera(int nodeIndex, const tinygltf::Node& node, const glm::dmat4& world) {
    const auto& model = ctx_.model;
    const std::string where = describe("node", nodeIndex, node.name);
    if (size_t(node.camera) >= model.cameras.size()) {
      ctx_.fail(where + ": camera " + std::to_string(node.camera) + " is out of range (the file has " +
                std::to_string(model.cameras.size()) + " cameras)");
    }
    const tinygltf::Camera& gc = model.cameras[size_t(node.camera)];
    const std::string cam = describe("camera", node.camera, gc.name);
    Camera c;
    c.name = !gc.name.empty() ? gc.name : !node.name.empty() ? node.name : "camera" + std::to_string(node.camera);
    if (gc.type == "perspective") {
      const auto& p = gc.perspective;
      if (!(p.yfov > 0.0) || !(p.znear > 0.0)) ctx_.fail(cam + ": perspective yfov and znear must be > 0");
      c.projection = Projection::Perspective;
      c.yfov = float(p.yfov);
      c.znear = float(p.znear);
      c.zfar = p.zfar > p.znear ? float(p.zfar) : 0.0f;
      c.fileAspectRatio = float(p.aspectRatio);
    } else if (gc.type == "orthographic") {
      const auto& o = gc.orthographic;
      if (o.xmag == 0.0 || o.ymag == 0.0 || !(o.zfar > o.znear)) {
        ctx_.fail(cam + ": orthographic xmag and ymag must be non-zero and zfar > znear");
      }
      c.projection = Projection::Orthographic;
      c.xmag = float(std::abs(o.xmag));
      c.ymag = float(std::abs(o.ymag));
      c.znear = float(o.znear);
      c.zfar = float(o.zfar);
    } else {
      ctx_.fail(cam + ": unknown camera type '" + gc.type + "'");
    }
    // Cameras are rigid (spec 3.10.1): strip any scale inherited from parents (Duck's camera
    // sits under a 0.01-scaled node) so view() is a pure rotation and translation.
    glm::mat4 m(world);
    for (int axis = 0; axis < 3; ++axis) {
      glm::vec3 col = safeNormalize(glm::vec3(m[axis]), glm::vec3(axis == 0, axis == 1, axis == 2));
      m[axis] = glm::vec4(col, 0.0f);
    }
    c.cameraToWorld = m;
    ctx_.scene.cameras.push_back(std::move(c));
  }

  void addLight(int nodeIndex, const tinygltf::Node& node, int lightIndex, const glm::dmat4& world) {
    const auto& model = ctx_.model;
    const std::string where = describe("node", nodeIndex, node.name);
    if (lightIndex < 0 || size_t(lightIndex) >= model.lights.size()) {
      ctx_.fail(where + ": KHR_lights_punctual light " + std::to_string(lightIndex) + " is out of range (the file has " +
                std::to_string(model.lights.size()) + " lights)");
    }
    const tinygltf::Light& gl = model.lights[size_t(lightIndex)];
    PunctualLight l;
    l.name = !gl.name.empty() ? gl.name : "light" + std::to_string(lightIndex);
    if (gl.type == "point") {
      l.type = LightType::Point;
    } else if (gl.type == "spot") {
      l.type = LightType::Spot;
      l.innerConeAngle = float(gl.spot.innerConeAngle);
      l.outerConeAngle = float(gl.spot.outerConeAngle);
    } else if (gl.type == "directional") {
      l.type = LightType::Directional;
    } else {
      ctx_.fail(describe("light", lightIndex, gl.name) + ": unknown type '" + gl.type + "'");
    }
    if (gl.color.size() == 3) l.color = glm::vec3(gl.color[0], gl.color[1], gl.color[2]);
    l.intensity = float(gl.intensity);
    if (gl.range > 0.0) l.range = float(gl.range);
    // The light sits at the node origin and shines down the node's -Z (extension spec).
    l.position = glm::vec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    l.direction = safeNormalize(glm::vec3(world * glm::dvec4(0.0, 0.0, -1.0, 0.0)), glm::vec3(0.0f, 0.0f, -1.0f));
    ctx_.scene.lights.push_back(std::move(l));
  }

  Context& ctx_;
  gltf::AccessorReader accessors_;
  std::vector<bool> onPath_;
  bool anyColors_ = false;
  bool anyTangents_ = false;
};

// KHR_materials_variants: the names the file defines, and the index of the one asked for.
void selectVariant(Context& ctx, const std::string& name) {
  auto it = ctx.model.extensions.find("KHR_materials_variants");
  if (it != ctx.model.extensions.end() && it->second.Has("variants") && it->second.Get("variants").IsArray()) {
    const tinygltf::Value& list = it->second.Get("variants");
    for (size_t i = 0; i < list.ArrayLen(); ++i) {
      const tinygltf::Value& v = list.Get(int(i));
      ctx.scene.variants.push_back(v.Has("name") && v.Get("name").IsString() ? v.Get("name").Get<std::string>()
                                                                           : "variant " + std::to_string(i));
    }
  }
  if (name.empty()) return;
  auto found = std::find(ctx.scene.variants.begin(), ctx.scene.variants.end(), name);
  if (found == ctx.scene.variants.end()) {
    std::string known;
    for (const std::string& v : ctx.scene.variants) known += (known.empty() ? "" : ", ") + v;
    ctx.fail("has no material variant '" + name + "' (" +
             (known.empty() ? std::string("it defines none") : "it defines: " + known) + ")");
  }
  ctx.variant = int(found - ctx.scene.variants.begin());
  ctx.scene.variant = name;
}

}  // namespace

Scene loadGltf(const std::filesystem::path& path, const LoadOptions& options) {
  Scene scene;
  scene.source = path;
  std::vector<std::string> tinyWarnings;
  tinygltf::Model model = parse(path, tinyWarnings);
  Context ctx{model, path.string(), scene, {}};
  selectVariant(ctx, options.variant);

  // A required extension we cannot honour makes the file unrenderable; an optional one is
  // only ignored (glTF 2.0 spec 3.12).
  for (const std::string& ext : model.extensionsRequired) {
    if (!supported(ext)) {
      ctx.fail("requires extension " + ext + ", which parrender does not support (supported: " + supportedList() + ")");
    }
  }
  scene.extensionsUsed = model.extensionsUsed;
  for (const std::string& ext : model.extensionsUsed) {
    if (!supported(ext)) ctx.warn("optional extension " + ext + " is not supported and is ignored");
  }
  for (const std::string& w : tinyWarnings) {
    // Missing images are reported as errors when a texture uses them (loadTextures).
    if (w.rfind("Failed to load external 'uri' for image", 0) == 0 || w.rfind("File not found", 0) == 0) continue;
    ctx.warn(w);
  }

  gltf::loadTextures(ctx, model.images);
  gltf::loadMaterials(ctx);

  // The default scene: `scene` when given, else scene 0 (spec 3.4); with no scenes at all,
  // nothing is drawn, which is reported as an empty scene below.
  Flattener flattener(ctx);
  if (!model.scenes.empty()) {
    int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (size_t(sceneIndex) >= model.scenes.size()) {
      ctx.fail("scene " + std::to_string(sceneIndex) + " is out of range (the file has " +
               std::to_string(model.scenes.size()) + " scenes)");
    }
    for (int root : model.scenes[size_t(sceneIndex)].nodes) flattener.visit(root, glm::dmat4(1.0), 0);
  }
  flattener.finish();
  if (scene.triangles.empty()) ctx.fail("the default scene contains no triangles (nothing to render)");
  return scene;
}

}  // namespace pr::scene
