// Reading glTF accessors (internal to the loader): every component type, normalized integers,
// interleaved bufferViews (byteStride) and sparse substitution, with every byte range checked.
// tinygltf 2.7 parses sparse accessors but does not apply them, so this does.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/scene/gltf_context.h"

namespace pr::scene::gltf {

// Decoded accessor: count elements of `components` values each, row after row.
struct FloatAccessor {
  int components = 0;
  size_t count = 0;
  std::vector<float> values;
  const float* element(size_t i) const { return &values[i * size_t(components)]; }
};

// Caches decoded accessors by index: many meshes may share one accessor (the 98 spheres of
// MetalRoughSpheresNoTextures share one), and each node instance reads it again.
class AccessorReader {
 public:
  explicit AccessorReader(Context& context) : context_(context) {}

  // Attribute data as floats (normalized integers mapped to [0,1] or [-1,1], other integers
  // converted as values). `what` names the use ("mesh 0 primitive 1 POSITION") for messages.
  // Non-finite values are an input error.
  const FloatAccessor& floats(int accessor, const std::string& what);

  // Index data: a SCALAR accessor of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT.
  const std::vector<uint32_t>& indices(int accessor, const std::string& what);

 private:
  // Every component of every element as double (exact for all glTF integer types).
  std::vector<double> decode(int accessor, const std::string& what, int* components, bool applyNormalized);

  Context& context_;
  std::unordered_map<int, FloatAccessor> floats_;
  std::unordered_map<int, std::vector<uint32_t>> indices_;
};

}  // namespace pr::scene::gltf
