// Test support: writes small glTF files from a test (JSON text with one base64 data: buffer)
// into a scratch directory, so loader tests state their geometry next to their expectations.
// Also the catalogue of bad input files shared by the loader and `parrender info` tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pr::test {

inline std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    uint32_t v = uint32_t(bytes[i]) << 16 | uint32_t(bytes[i + 1]) << 8 | bytes[i + 2];
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (size_t rest = bytes.size() - i; rest > 0) {
    uint32_t v = uint32_t(bytes[i]) << 16 | (rest == 2 ? uint32_t(bytes[i + 1]) << 8 : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// An 8-bit RGBA PNG of the given texels (row 0 on top), uncompressed (stored deflate blocks):
// enough for tinygltf's decoder, without an image library in the tests. Written with resize
// and memcpy: GCC 12 reports false -Warray-bounds on vector::insert of byte ranges here.
inline std::vector<uint8_t> encodePng(int width, int height, const std::vector<uint8_t>& rgba) {
  auto append = [](std::vector<uint8_t>& out, const void* data, size_t n) {
    size_t at = out.size();
    out.resize(at + n);
    if (n) std::memcpy(out.data() + at, data, n);
  };
  auto be32 = [&](std::vector<uint8_t>& out, uint32_t v) {
    uint8_t b[4] = {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)};
    append(out, b, 4);
  };
  auto crc32 = [](const std::vector<uint8_t>& bytes) {
    uint32_t crc = 0xffffffffu;
    for (uint8_t byte : bytes) {
      crc ^= byte;
      for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    return ~crc;
  };
  // Scanlines: filter type 0 (none), then the row's texels.
  const size_t rowBytes = size_t(width) * 4;
  std::vector<uint8_t> raw(size_t(height) * (rowBytes + 1), 0);
  for (size_t y = 0; y < size_t(height); ++y) std::memcpy(&raw[y * (rowBytes + 1) + 1], &rgba[y * rowBytes], rowBytes);
  // zlib stream: header, stored deflate blocks of at most 65535 bytes, Adler-32.
  std::vector<uint8_t> z = {0x78, 0x01};
  size_t at = 0;
  do {
    size_t n = std::min<size_t>(raw.size() - at, 65535);
    uint8_t header[5] = {uint8_t(at + n == raw.size() ? 1 : 0), uint8_t(n), uint8_t(n >> 8), uint8_t(~n), uint8_t(~n >> 8)};
    append(z, header, 5);
    append(z, raw.data() + at, n);
    at += n;
  } while (at < raw.size());
  uint32_t a = 1, b = 0;
  for (uint8_t c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  be32(z, b << 16 | a);
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto chunk = [&](const char* type, const std::vector<uint8_t>& data) {
    be32(png, uint32_t(data.size()));
    std::vector<uint8_t> body;
    append(body, type, 4);
    append(body, data.data(), data.size());
    append(png, body.data(), body.size());
    be32(png, crc32(body));
  };
  std::vector<uint8_t> ihdr;
  be32(ihdr, uint32_t(width));
  be32(ihdr, uint32_t(height));
  const uint8_t format[5] = {8, 6, 0, 0, 0};  // 8 bits, RGBA, deflate, no filter, no interlace
  append(ihdr, format, 5);
  chunk("IHDR", ihdr);
  chunk("IDAT", z);
  chunk("IEND", {});
  return png;
}

// Builds one glTF document: binary data goes into buffer 0 (written as a data: URI),
// everything else is edited directly in `doc`.
class GltfWriter {
 public:
  nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};

  // Appends raw bytes (4-byte aligned) as a new bufferView; returns its index.
  int addView(const void* data, size_t bytes, int byteStride = 0) {
    while (bin_.size() % 4) bin_.push_back(0);
    nlohmann::json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes}};
    if (byteStride) view["byteStride"] = byteStride;
    const auto* p = static_cast<const uint8_t*>(data);
    bin_.insert(bin_.end(), p, p + bytes);
    doc["bufferViews"].push_back(view);
    return int(doc["bufferViews"].size()) - 1;
  }

  int addAccessor(int view, int componentType, size_t count, const std::string& type, size_t byteOffset = 0,
                  bool normalized = false) {
    nlohmann::json a = {{"componentType", componentType}, {"count", count}, {"type", type}};
    if (view >= 0) a["bufferView"] = view;
    if (byteOffset) a["byteOffset"] = byteOffset;
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size()) - 1;
  }

  int addFloats(const std::vector<float>& values, const std::string& type) {
    int components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
    int view = addView(values.data(), values.size() * sizeof(float));
    return addAccessor(view, 5126, values.size() / size_t(components), type);
  }

  int addIndices(const std::vector<uint16_t>& indices) {
    int view = addView(indices.data(), indices.size() * sizeof(uint16_t));
    return addAccessor(view, 5123, indices.size(), "SCALAR");
  }

  // A mesh with one primitive; returns the mesh index.
  int addMesh(nlohmann::json attributes, int indices = -1, int mode = 4, int material = -1) {
    nlohmann::json prim = {{"attributes", attributes}, {"mode", mode}};
    if (indices >= 0) prim["indices"] = indices;
    if (material >= 0) prim["material"] = material;
    doc["meshes"].push_back({{"primitives", {prim}}});
    return int(doc["meshes"].size()) - 1;
  }

  int addNode(nlohmann::json node) {
    doc["nodes"].push_back(node);
    return int(doc["nodes"].size()) - 1;
  }

  // A scene 0 with the given root nodes.
  void setRoots(const std::vector<int>& roots) { doc["scenes"] = {{{"nodes", roots}}}; doc["scene"] = 0; }

  std::filesystem::path write(const std::filesystem::path& dir, const std::string& name) {
    nlohmann::json out = doc;
    if (!bin_.empty()) {
      out["buffers"] = {{{"byteLength", bin_.size()},
                         {"uri", "data:application/octet-stream;base64," + base64(bin_)}}};
    }
    auto path = dir / name;
    std::ofstream(path) << out.dump(1);
    return path;
  }

 private:
  std::vector<uint8_t> bin_;
};

// One triangle in the z = 0 plane facing +Z: the smallest valid drawable file.
inline GltfWriter oneTriangle() {
  GltfWriter w;
  int pos = w.addFloats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  int mesh = w.addMesh({{"POSITION", pos}});
  w.setRoots({w.addNode({{"mesh", mesh}})});
  return w;
}

// The one-triangle file written as `name` with buffer 0's URI replaced by `uri` (the writer
// itself always embeds the buffer as a data URI).
inline std::filesystem::path oneTriangleWithBufferUri(const std::filesystem::path& dir, const std::string& name,
                                                      const std::string& uri) {
  auto path = oneTriangle().write(dir, name);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(path));
  doc["buffers"][0]["uri"] = uri;
  std::ofstream(path) << doc.dump(1);
  return path;
}

// A bad input file and the words its error message must contain (besides the file name).
struct BadInput {
  std::string name;
  std::filesystem::path path;
  std::string expected;
  uint64_t maxMemory = 0;  // the memory limit to load under (bytes); 0 = the default
};

// A GLB container (spec 4.4): the header, then each chunk (type, bytes) padded to 4 bytes.
inline std::vector<uint8_t> glbContainer(const std::vector<std::pair<uint32_t, std::string>>& chunks) {
  std::vector<uint8_t> out = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 0, 0, 0, 0};
  auto le32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
  };
  for (const auto& [type, body] : chunks) {
    std::string padded = body;
    while (padded.size() % 4) padded += type == 0x4E4F534Au ? ' ' : '\0';
    le32(uint32_t(padded.size()));
    le32(type);
    out.insert(out.end(), padded.begin(), padded.end());
  }
  const uint32_t total = uint32_t(out.size());
  for (int i = 0; i < 4; ++i) out[8 + size_t(i)] = uint8_t(total >> (8 * i));
  return out;
}
inline constexpr uint32_t kGlbJson = 0x4E4F534Au, kGlbBin = 0x004E4942u;

// The one-triangle file as a GLB: its buffer 0 becomes the BIN chunk.
inline std::vector<uint8_t> oneTriangleGlb(std::vector<std::pair<uint32_t, std::string>> extraChunks = {},
                                           bool withBin = true) {
  nlohmann::json doc = {{"asset", {{"version", "2.0"}}},
                        {"buffers", {{{"byteLength", 36}}}},
                        {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                        {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
                        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
                        {"nodes", {{{"mesh", 0}}}},
                        {"scenes", {{{"nodes", {0}}}}}};
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<std::pair<uint32_t, std::string>> chunks = {{kGlbJson, doc.dump()}};
  if (withBin) chunks.push_back({kGlbBin, std::string(reinterpret_cast<const char*>(positions), sizeof positions)});
  chunks.insert(chunks.end(), extraChunks.begin(), extraChunks.end());
  return glbContainer(chunks);
}

inline std::filesystem::path writeBytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  return path;
}

// Writes one file per kind of bad input the loader must reject with an InputError.
inline std::vector<BadInput> writeBadInputs(const std::filesystem::path& dir) {
  std::vector<BadInput> bad;
  bad.push_back({"missing file", dir / "does_not_exist.gltf", "no such file"});
  {
    auto path = dir / "malformed.gltf";
    std::ofstream(path) << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ {";
    bad.push_back({"malformed JSON", path, "not a valid glTF"});
  }
  {
    auto path = dir / "truncated.glb";
    std::ofstream(path, std::ios::binary) << "glTF\x02\x00\x00\x00garbage";
    bad.push_back({"truncated glb", path, "not a valid glTF binary"});
  }
  {
    auto path = oneTriangleWithBufferUri(dir, "missing_buffer.gltf", "missing_buffer.bin");
    bad.push_back({"missing buffer file", path, "buffer file 'missing_buffer.bin' is missing"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    w.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    bad.push_back({"unsupported required extension", w.write(dir, "required_ext.gltf"),
                   "requires extension KHR_draco_mesh_compression"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 7;
    bad.push_back({"accessor index out of range", w.write(dir, "accessor_index.gltf"), "accessor 7 is out of range"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["accessors"][0]["count"] = 4;  // 4 VEC3 floats = 48 bytes, the view has 36
    bad.push_back({"accessor past its bufferView", w.write(dir, "accessor_range.gltf"), "bufferView 0 has 36"});
  }
  {
    // Legal glTF, but past 32-bit vertex indices: refused on the declared count, before the
    // (absent) data is read.
    GltfWriter w = oneTriangle();
    w.doc["accessors"][0]["count"] = 4294967295ull;
    bad.push_back({"more vertices than 32-bit indices", w.write(dir, "vertex_limit.gltf"),
                   "4294967295 vertices in the scene exceed the limit of 4294967294"});
  }
  {
    GltfWriter w;
    int pos = w.addFloats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    int idx = w.addIndices({0, 1, 2});
    w.doc["accessors"][size_t(idx)]["count"] = 3ull * 4294967296ull;
    w.setRoots({w.addNode({{"mesh", w.addMesh({{"POSITION", pos}}, idx)}})});
    bad.push_back({"more triangles than 32-bit indices", w.write(dir, "triangle_limit.gltf"),
                   "4294967296 triangles in the scene exceed the limit of 4294967294"});
  }
  {
    GltfWriter w;
    int pos = w.addFloats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    int idx = w.addIndices({0, 1, 5});
    w.setRoots({w.addNode({{"mesh", w.addMesh({{"POSITION", pos}}, idx)}})});
    bad.push_back({"index out of range", w.write(dir, "index_range.gltf"), "index 5 is out of range"});
  }
  {
    GltfWriter w;
    float nan = std::numeric_limits<float>::quiet_NaN();
    int pos = w.addFloats({0, 0, 0, 1, nan, 0, 0, 1, 0}, "VEC3");
    w.setRoots({w.addNode({{"mesh", w.addMesh({{"POSITION", pos}})}})});
    bad.push_back({"NaN vertex", w.write(dir, "nan_vertex.gltf"), "element 1 is not a finite number"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["images"] = {{{"uri", "missing_texture.png"}}};
    w.doc["textures"] = {{{"source", 0}}};
    w.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    w.doc["meshes"][0]["primitives"][0]["material"] = 0;
    bad.push_back({"missing texture file", w.write(dir, "missing_texture.gltf"),
                   "texture file 'missing_texture.png' is missing"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["nodes"][0].erase("mesh");  // a scene whose only node draws nothing
    bad.push_back({"empty scene", w.write(dir, "empty_scene.gltf"), "contains no triangles"});
  }
  // Hostile files: each would read outside the model's folder, take time exponential in its
  // size, or allocate far more than it holds.
  {
    auto path = oneTriangleWithBufferUri(dir, "escape.gltf", "../../../../../../etc/passwd");
    bad.push_back({"buffer URI escaping the folder", path, "refers to '../../../../../../etc/passwd', outside the model's folder"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["images"] = {{{"uri", "..%2F..%2Fsecret.png"}}};  // percent-encoded "../../secret.png"
    w.doc["textures"] = {{{"source", 0}}};
    bad.push_back({"percent-encoded image URI escaping the folder", w.write(dir, "escape_encoded.gltf"),
                   "refers to '../../secret.png', outside the model's folder"});
  }
  {
    // Node i has node i+1 as its child twice over (through two parents): 2^40 paths to the
    // last node if it were walked as a graph.
    GltfWriter w = oneTriangle();
    for (int i = 1; i <= 80; i += 2) {
      w.doc["nodes"][size_t(i - 1)]["children"] = {i, i + 1};
      w.addNode({{"children", {i + 1}}});
      w.addNode({{"mesh", 0}});
    }
    bad.push_back({"node with two parents", w.write(dir, "node_dag.gltf"), "one parent each"});
  }
  {
    // A chain of 1002 nodes (root at depth 0): one level past the 1000 the loader walks.
    GltfWriter w = oneTriangle();
    w.doc["nodes"][0].erase("mesh");
    for (int i = 1; i <= 1001; ++i) {
      w.doc["nodes"][size_t(i - 1)]["children"] = {i};
      w.addNode(i == 1001 ? nlohmann::json{{"mesh", 0}} : nlohmann::json::object());
    }
    bad.push_back({"node hierarchy too deep", w.write(dir, "deep.gltf"), "hierarchy deeper than 1000 levels"});
  }
  {
    // Two nested scales of 1e200: the world matrix holds inf, and inf * 0 makes a NaN vertex.
    GltfWriter w = oneTriangle();
    w.doc["nodes"][0].erase("mesh");
    w.doc["nodes"][0]["scale"] = {1, 1e200, 1};
    w.doc["nodes"][0]["children"] = {1};
    w.addNode({{"mesh", 0}, {"scale", {1, 1e200, 1}}});
    bad.push_back({"transform overflowing to NaN", w.write(dir, "nan_transform.gltf"), "or is not finite after the node transforms"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    w.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 1}}};
    w.addNode({{"translation", {0, 3e18, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    w.doc["scenes"][0]["nodes"] = {0, 1};
    bad.push_back({"light beyond the coordinate range", w.write(dir, "far_light.gltf"), "the light lies beyond +-1e18"});
  }
  bad.push_back({"absolute buffer URI", oneTriangleWithBufferUri(dir, "absolute_uri.gltf", "/etc/passwd"),
                 "refers to '/etc/passwd', outside the model's folder"});
  {
    GltfWriter w = oneTriangle();
    w.addNode({{"mesh", 0}});
    w.doc["nodes"][0]["children"] = {1, 1};
    bad.push_back({"child listed twice", w.write(dir, "child_twice.gltf"), "node 0 lists child 1 twice"});
  }
  {
    GltfWriter w = oneTriangle();
    w.doc["scenes"][0]["nodes"] = {0, 0};
    bad.push_back({"scene root listed twice", w.write(dir, "root_twice.gltf"), "lists node 0 twice"});
  }
  {
    GltfWriter w = oneTriangle();
    w.addNode({{"children", {0}}});
    w.doc["scenes"][0]["nodes"] = {0, 1};
    bad.push_back({"scene root that is a child", w.write(dir, "root_child.gltf"), "is a scene root but also a child of node 1"});
  }
  {
    // A sparse accessor without a bufferView: 16 million zero vectors from a few bytes.
    GltfWriter w = oneTriangle();
    const uint32_t index = 0;
    const float value[3] = {0, 0, 0};
    int indexView = w.addView(&index, 4), valueView = w.addView(value, 12);
    w.doc["accessors"][0] = {{"componentType", 5126}, {"count", 1 << 24}, {"type", "VEC3"},
                             {"sparse", {{"count", 1}, {"indices", {{"bufferView", indexView}, {"componentType", 5125}}},
                                         {"values", {{"bufferView", valueView}}}}}};
    bad.push_back({"accessor over the memory limit", w.write(dir, "sparse_huge.gltf"),
                   "accessor 0 needs 576.0 MiB", uint64_t(64) << 20});
  }
  {
    // PNG headers claiming 8192 x 8192 pixels (under stb_image's own 2^30-byte cap, so refused
    // by the memory limit) and 65535 x 65535 (over it): refused from the header, never decoded.
    for (int edge : {8192, 65535}) {
      GltfWriter w = oneTriangle();
      std::vector<uint8_t> png = encodePng(1, 1, {255, 255, 255, 255});
      for (size_t offset : {16, 20}) png[offset + 2] = uint8_t(edge >> 8), png[offset + 3] = uint8_t(edge);
      w.doc["images"] = {{{"uri", "data:image/png;base64," + base64(png)}}};
      w.doc["textures"] = {{{"source", 0}}};
      if (edge == 8192) {
        bad.push_back({"image over the memory limit", w.write(dir, "image_huge.gltf"),
                       "image 0 (8192 x 8192 pixels) needs 512.0 MiB", uint64_t(64) << 20});
      } else {
        bad.push_back({"image over stb_image's limit", w.write(dir, "image_enormous.gltf"), "image 0 cannot be decoded (corrupt, not PNG or JPEG, or over stb_image's 2^30-byte limit)"});
      }
    }
  }
  {
    auto path = oneTriangleWithBufferUri(dir, "bad_base64.gltf", "data:application/octet-stream;base64,@@@@not*base64");
    bad.push_back({"data URI with bad base64", path, "not a valid glTF file"});
  }
  {
    // A .gltf whose buffer file is itself a GLB: a different file, not raw buffer bytes.
    writeBytes(dir / "inner.glb", oneTriangleGlb());
    auto path = oneTriangleWithBufferUri(dir, "buffer_is_glb.gltf", "inner.glb");
    bad.push_back({"buffer file that is a GLB", path, "'inner.glb' is a binary glTF (.glb), not a raw buffer"});
  }
  bad.push_back({"GLB without its BIN chunk", writeBytes(dir / "no_bin.glb", oneTriangleGlb({}, false)), "not a valid glTF binary"});
  return bad;
}

}  // namespace pr::test
