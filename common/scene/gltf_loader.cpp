// glTF 2.0 into the render-ready Scene (runs once, before any PE starts): parses with
// tinygltf, checks required extensions, walks the default scene's node hierarchy and
// flattens every drawn mesh primitive, light and camera into world space.
// Geometry rules: glTF 2.0 spec 3.5 (transforms), 3.7.2 (primitive modes, winding).
#include "common/scene/gltf_loader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <span>

#include <stb/stb_image.h>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "common/scene/gltf_accessor.h"
#include "common/scene/gltf_context.h"
#include "common/scene/gltf_material.h"
#include "common/scene/tangent_frame.h"
#include "common/util/limits.h"
#include "common/util/memory_limit.h"

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
// Divided by its largest component first, so that neither a denormal nor a huge vector loses
// its length to underflow or overflow in the squares.
glm::vec3 safeNormalize(glm::vec3 v, glm::vec3 fallback) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return fallback;  // max() would drop a NaN
  const float largest = std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z)));
  if (!(largest > 0.0f)) return fallback;
  v /= largest;
  return v / glm::length(v);
}

// World coordinates beyond this are refused: the tracers and rasterizers square distances in
// float, which overflows past about 1.8e19; 1e18 keeps a factor of 10 in hand for sums.
constexpr double kMaxCoordinate = 1e18;

// Finite and within kMaxCoordinate on every axis (each compared: max() would drop a NaN).
bool withinRange(const glm::dvec3& q) {
  return std::abs(q.x) <= kMaxCoordinate && std::abs(q.y) <= kMaxCoordinate && std::abs(q.z) <= kMaxCoordinate;
}

// The whole file, charged to the budget (as `what`) before it is read: the model itself, and
// each buffer or image file it refers to.
std::vector<uint8_t> readFile(const std::filesystem::path& path, MemoryBudget& budget, const std::string& what) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(file + ": cannot read the file (" +
                     (std::filesystem::exists(path, ec) ? "not a regular file" : "no such file") + ")");
  }
  const uintmax_t size = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) throw InputError(file + ": cannot read the file (permission denied or unreadable)");
  budget.charge(size, what);
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
    throw InputError(file + ": cannot read the file (read failed)");
  return bytes;
}

// External files (buffers, images) the file refers to, read through tinygltf's file-system
// callbacks so that every one is confined to the model's folder and charged to the budget.
struct FileAccess {
  std::filesystem::path folder;  // empty: no external files at all (loading from memory)
  MemoryBudget* budget = nullptr;
  std::string refusal;  // the first refused reference; reported as the load's error
  const tinygltf::Model* model = nullptr;  // being parsed: its buffers are read when images are

  // What tinygltf joins every URI to (folder + "/"). Its second probe of the working directory
  // ("./uri") has another prefix unless the folder is ".", so it is never answered.
  std::string prefix() const {
    std::string p = folder.string();
    if (!p.empty() && p.back() != '/') p += '/';
    return p;
  }

  // The URI part of a joined path, lexically normalised, or "" when the path is not a join of
  // the folder, or leads outside it: by "..", as an absolute URI, or through a symlink (the
  // file the kernel would open must lie under the folder's real path too).
  std::filesystem::path inside(const std::string& path) const {
    namespace fs = std::filesystem;
    if (folder.empty() || path.rfind(prefix(), 0) != 0) return {};
    const fs::path rel = fs::path(path.substr(prefix().size())).lexically_normal();
    if (rel.empty() || rel.is_absolute() || *rel.begin() == "..") return {};
    std::error_code e1, e2;
    const fs::path real = fs::weakly_canonical(path, e1), root = fs::weakly_canonical(folder, e2);
    if (e1 || e2) return {};
    const fs::path fromRoot = real.lexically_relative(root);
    if (fromRoot.empty() || *fromRoot.begin() == "..") return {};
    return rel;
  }

  bool allowed(const std::string& path) {
    if (!inside(path).empty()) return true;
    // Only a join of the folder is the file's own reference; tinygltf's other probes are not.
    const bool joined = !folder.empty() && path.rfind(prefix(), 0) == 0;
    if (refusal.empty() && (joined || folder.empty()) && !path.empty()) {
      const std::string uri = folder.empty() ? path : path.substr(prefix().size());
      refusal = folder.empty() ? "refers to the external file '" + uri + "', but a model loaded from memory has no folder"
                               : "refers to '" + uri + "', outside the model's folder (or through a link out of it); refused";
    }
    return false;
  }

  // tinygltf URI-decodes with form rules, '+' becoming a space; a file whose name has a real
  // '+' is found under its spaces turned back into '+'.
  std::string resolve(const std::string& path) const {
    std::error_code ec;
    std::string uri = inside(path).string();
    if (std::filesystem::is_regular_file(path, ec) || uri.find(' ') == std::string::npos) return path;
    std::replace(uri.begin(), uri.end(), ' ', '+');
    const std::filesystem::path plus = folder / uri;
    return std::filesystem::is_regular_file(plus, ec) ? plus.string() : path;
  }

  static bool exists(const std::string& path, void* self) {
    auto& access = *static_cast<FileAccess*>(self);
    std::error_code ec;
    return access.allowed(path) && std::filesystem::is_regular_file(access.resolve(path), ec);
  }
  static std::string expand(const std::string& path, void*) { return path; }  // no ~ or $VAR
  static bool read(std::vector<unsigned char>* out, std::string* /*err: reported as the refusal*/, const std::string& uriPath, void* self) {
    auto& access = *static_cast<FileAccess*>(self);
    if (!access.allowed(uriPath)) return false;
    const std::string path = access.resolve(uriPath);
    try {
      *out = readFile(path, *access.budget, "file '" + access.inside(path).string() + "'");
    } catch (const InputError& e) {
      if (access.refusal.empty()) access.refusal = e.what();
      return false;
    }
    // A GLB's header (magic, version 2, its own length) where raw bytes were expected: the
    // accessors would read the container's header and JSON as vertex data.
    uint32_t header[3] = {};
    if (out->size() >= 12) std::memcpy(header, out->data(), 12);
    if (out->size() >= 12 && std::memcmp(out->data(), "glTF", 4) == 0 && header[1] == 2 && header[2] == out->size()) {
      if (access.refusal.empty()) {
        access.refusal = "'" + access.inside(path).string() + "' is a binary glTF (.glb), not a raw buffer or image; load the .glb itself";
      }
      return false;
    }
    return true;
  }
  static bool write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err = "the loader never writes";
    return false;
  }

  // tinygltf's decoder after a look at the header: an image whose decoded pixels would exceed
  // the budget is refused before stb_image allocates them.
  static bool decodeImage(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int width,
                          int height, const unsigned char* bytes, int size, void* self) {
    auto& access = *static_cast<FileAccess*>(self);
    // tinygltf checks an image's bufferView and buffer indices but not that the view lies in
    // its buffer: `bytes` may point past the end. Checked here before anything is read.
    if (image->bufferView >= 0) {
      const tinygltf::BufferView& view = access.model->bufferViews[size_t(image->bufferView)];
      const size_t length = access.model->buffers[size_t(view.buffer)].data.size();
      if (view.byteOffset > length || view.byteLength > length - view.byteOffset) {
        if (err) {
          *err += "image " + std::to_string(index) + ": bufferView " + std::to_string(image->bufferView) + " (bytes " +
                  std::to_string(view.byteOffset) + ".." + std::to_string(view.byteOffset + view.byteLength) +
                  ") exceeds buffer " + std::to_string(view.buffer) + " of " + std::to_string(length) + " bytes\n";
        }
        return false;
      }
    }
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &channels)) {
      // stb_image tries every format it knows, so its last reason is rarely the one that counts.
      if (err) {
        *err += "image " + std::to_string(index) +
                " cannot be decoded (corrupt, not PNG or JPEG, or over stb_image's 2^30-byte limit)\n";
      }
      return false;
    }
    {
      const uint64_t texel = stbi_is_16_bit_from_memory(bytes, size) ? 8 : 4;  // decoded as RGBA
      try {
        // Twice: tinygltf's decoded copy, and the scene's 8-bit RGBA texture made from it.
        access.budget->charge(saturatingMul(saturatingMul(uint64_t(w), uint64_t(h)), texel + 4),
                              "image " + std::to_string(index) + " (" + std::to_string(w) + " x " +
                                  std::to_string(h) + " pixels)");
      } catch (const InputError& e) {
        if (access.refusal.empty()) access.refusal = e.what();
        if (err) *err += e.what();
        return false;
      }
    }
    return tinygltf::LoadImageData(image, index, err, warn, width, height, bytes, size, nullptr);
  }
};

// Parses the bytes with tinygltf; anything it rejects is one InputError naming the file.
tinygltf::Model parse(std::span<const uint8_t> bytes, const std::string& file, FileAccess& access,
                      std::vector<std::string>& tinyWarnings) {
  // A .glb starts with the magic "glTF" (spec 4.4.2); anything else is parsed as JSON.
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  if (bytes.size() > size_t(std::numeric_limits<unsigned int>::max()))
    throw InputError(file + ": " + std::to_string(bytes.size()) + " bytes is larger than glTF's 4 GiB limit");

  tinygltf::TinyGLTF parser;
  parser.SetFsCallbacks({&FileAccess::exists, &FileAccess::expand, &FileAccess::read, &FileAccess::write, &access});
  parser.SetImageLoader(&FileAccess::decodeImage, &access);
  tinygltf::Model model;
  access.model = &model;
  std::string err, warn;
  const std::string folder = access.folder.empty() ? std::string() : access.folder.string();
  bool ok = binary ? parser.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), folder)
                   : parser.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                                unsigned(bytes.size()), folder);
  if (!access.refusal.empty()) throw InputError(file + ": " + access.refusal);
  if (!ok) {
    // tinygltf reports several lines; the first names the actual problem.
    std::string reason = err.empty() ? "unknown parse error" : err.substr(0, err.find('\n'));
    // tinygltf quotes the offending value, which may be a multi-megabyte data URI.
    constexpr size_t kMaxReason = 240;
    if (reason.size() > kMaxReason) reason = reason.substr(0, kMaxReason) + "... (" + std::to_string(reason.size()) + " characters)";
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
      const std::string what = describe("node", index, node.name) + ": KHR_lights_punctual light";
      addLight(index, node, wholeNumber(ctx_, it->second.Get("light"), what), world);
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
    ctx_.charge(saturatingMul(declared, sizeof(uint32_t)) + saturatingMul(triangles, sizeof(uint32_t) * 3), where + " triangle list");
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
      if (!m.Has("variants") || !m.Get("variants").IsArray() || !m.Has("material")) continue;
      const tinygltf::Value& vs = m.Get("variants");
      for (size_t k = 0; k < vs.ArrayLen(); ++k) {
        if (wholeNumber(ctx_, vs.Get(int(k)), where + ": KHR_materials_variants variant") != ctx_.variant) continue;
        const int material = wholeNumber(ctx_, m.Get("material"), where + ": KHR_materials_variants material");
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
    // Every drawn instance is a copy in world space: positions, normals, uvs, colours,
    // tangents, the generated-normal scratch and the triangles.
    constexpr uint64_t kVertexBytes = 2 * sizeof(glm::vec3) + sizeof(glm::vec2) + 2 * sizeof(glm::vec4) + sizeof(glm::vec3);
    ctx_.charge(saturatingMul(count, kVertexBytes) + saturatingMul(local.size() / 3, sizeof(Triangle)),
                describe("node", nodeIndex, node.name) + " " + where);

    // World-space vertices. A mirroring transform (det < 0) reverses the apparent winding, so
    // triangles are re-wound below; normals transform by the inverse transpose (spec 3.5.2).
    Scene& s = ctx_.scene;
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
    const glm::mat3 normalMatrix(glm::transpose(glm::inverse(glm::dmat3(world))));
    const uint32_t base = uint32_t(s.positions.size());
    PR_CHECK(s.positions.size() + count <= kMaxVertices, "scene exceeds kMaxVertices (checked above)");
    for (size_t i = 0; i < count; ++i) {
      const float* p = pos.element(i);
      const glm::dvec3 q(world * glm::dvec4(p[0], p[1], p[2], 1.0));
      if (!withinRange(q)) {
        ctx_.fail(describe("node", nodeIndex, node.name) + " " + where + ": vertex " + std::to_string(i) +
                  " lies beyond +-1e18 in world space (or is not finite after the node transforms); "
                  "squared distances would overflow float");
      }
      s.positions.push_back(glm::vec3(q));
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
    if (!withinRange(glm::dvec3(world[3]))) ctx_.fail(where + ": the camera lies beyond +-1e18 in world space (or is not finite)");
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
    if (!withinRange(glm::dvec3(world[3]))) ctx_.fail(where + ": the light lies beyond +-1e18 in world space (or is not finite)");
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

// glTF nodes form disjoint strict trees (spec 3.5.1) and a scene lists each root once: so a
// walk from the roots visits every node at most once. A node with two parents (a DAG that
// would multiply the visits exponentially) or a scene root that is someone's child is refused.
void checkNodeForest(const Context& ctx) {
  const auto& nodes = ctx.model.nodes;
  std::vector<int> parent(nodes.size(), -1);
  for (size_t p = 0; p < nodes.size(); ++p) {
    for (int child : nodes[p].children) {
      if (child < 0 || size_t(child) >= nodes.size()) {
        ctx.fail(describe("node", int(p), nodes[p].name) + ": child " + std::to_string(child) +
                 " is out of range (the file has " + std::to_string(nodes.size()) + " nodes)");
      }
      if (parent[size_t(child)] == int(p))
        ctx.fail(describe("node", int(p), nodes[p].name) + " lists child " + std::to_string(child) + " twice");
      if (parent[size_t(child)] >= 0) {
        ctx.fail(describe("node", child, nodes[size_t(child)].name) + " is a child of both node " +
                 std::to_string(parent[size_t(child)]) + " and node " + std::to_string(p) +
                 " (glTF nodes form trees: one parent each)");
      }
      parent[size_t(child)] = int(p);
    }
  }
  for (size_t s = 0; s < ctx.model.scenes.size(); ++s) {
    std::vector<bool> listed(nodes.size(), false);
    for (int root : ctx.model.scenes[s].nodes) {
      const std::string where = describe("scene", int(s), ctx.model.scenes[s].name);
      if (root < 0 || size_t(root) >= nodes.size()) {
        ctx.fail(where + ": node " + std::to_string(root) + " is out of range (the file has " +
                 std::to_string(nodes.size()) + " nodes)");
      }
      if (listed[size_t(root)]) ctx.fail(where + " lists node " + std::to_string(root) + " twice");
      if (parent[size_t(root)] >= 0) {
        ctx.fail(where + ": node " + std::to_string(root) + " is a scene root but also a child of node " +
                 std::to_string(parent[size_t(root)]));
      }
      listed[size_t(root)] = true;
    }
  }
}

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

namespace {

Scene load(std::span<const uint8_t> bytes, const std::string& file, const std::filesystem::path& folder,
           const LoadOptions& options, MemoryBudget& budget) {
  Scene scene;
  std::vector<std::string> tinyWarnings;
  FileAccess access{folder, &budget, {}};
  // tinygltf copies a GLB's BIN chunk and decodes data URIs into buffers: about the file again.
  try {
    budget.charge(bytes.size(), "parsing (the copy of its buffers)");
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
  tinygltf::Model model = parse(bytes, file, access, tinyWarnings);
  Context ctx{model, file, scene, budget, {}};
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
  checkNodeForest(ctx);
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

}  // namespace

Scene loadGltf(const std::filesystem::path& path, const LoadOptions& options) {
  MemoryBudget budget(options.maxMemoryBytes);
  const std::vector<uint8_t> bytes = readFile(path, budget, path.string());
  // Relative URIs resolve against the file's folder (spec 3.6.1); "." for a bare file name.
  const std::filesystem::path folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  Scene scene = load(bytes, path.string(), folder.lexically_normal(), options, budget);
  scene.source = path;
  return scene;
}

Scene loadGltfFromMemory(std::span<const uint8_t> bytes, const std::string& name, const LoadOptions& options) {
  MemoryBudget budget(options.maxMemoryBytes);
  return load(bytes, name, {}, options, budget);
}

}  // namespace pr::scene
