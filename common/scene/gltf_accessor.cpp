// Accessor decoding for the glTF loader (glTF 2.0 spec, 3.6 "Binary data storage"): resolves
// accessor -> bufferView -> buffer with byteOffset and byteStride, converts every component
// type, applies `normalized` (3.11 equations) and sparse substitution, and range-checks it all.
#include "common/scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pr::scene::gltf {

namespace {

int componentBytes(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;  // INT and DOUBLE are not valid glTF accessor component types
  }
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

// One component; normalized integers follow the glTF 2.0 spec, 3.11 (signed: max(c / MAX, -1)).
double readComponent(const uint8_t* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? double(*p) / 255.0 : double(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? double(v) / 65535.0 : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? double(v) / 4294967295.0 : double(v);
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return double(v);
    }
  }
  return 0.0;
}

// The bytes of bufferView `index`, checked against its buffer.
struct ViewBytes {
  const uint8_t* data = nullptr;
  size_t length = 0;
  size_t stride = 0;  // 0 = tightly packed
};

ViewBytes viewBytes(const Context& ctx, int index, const std::string& where) {
  const auto& model = ctx.model;
  if (index < 0 || size_t(index) >= model.bufferViews.size()) {
    ctx.fail(where + ": bufferView " + std::to_string(index) + " is out of range (the file has " +
             std::to_string(model.bufferViews.size()) + ")");
  }
  const auto& view = model.bufferViews[size_t(index)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
    ctx.fail("bufferView " + std::to_string(index) + ": buffer " + std::to_string(view.buffer) +
             " is out of range (the file has " + std::to_string(model.buffers.size()) + ")");
  }
  const auto& buffer = model.buffers[size_t(view.buffer)];
  if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset) {
    ctx.fail("bufferView " + std::to_string(index) + ": bytes " + std::to_string(view.byteOffset) + ".." +
             std::to_string(view.byteOffset + view.byteLength) + " exceed buffer " + std::to_string(view.buffer) +
             " of " + std::to_string(buffer.data.size()) + " bytes");
  }
  return {buffer.data.data() + view.byteOffset, view.byteLength, view.byteStride};
}

}  // namespace

std::vector<double> AccessorReader::decode(int index, const std::string& what, int* components,
                                           bool applyNormalized) {
  const auto& model = context_.model;
  if (index < 0 || size_t(index) >= model.accessors.size()) {
    context_.fail(what + ": accessor " + std::to_string(index) + " is out of range (the file has " +
                  std::to_string(model.accessors.size()) + " accessors)");
  }
  const tinygltf::Accessor& acc = model.accessors[size_t(index)];
  const std::string where = what + ": accessor " + std::to_string(index);
  const int compBytes = componentBytes(acc.componentType);
  const int comps = componentCount(acc.type);
  if (compBytes == 0) context_.fail(where + ": invalid componentType " + std::to_string(acc.componentType));
  if (comps == 0) context_.fail(where + ": invalid type");
  const bool normalized = applyNormalized && acc.normalized;
  const size_t elementBytes = size_t(compBytes) * size_t(comps);
  *components = comps;

  // Base values: from the bufferView, or zeros when the accessor has none (sparse-only).
  // Ranges are checked before anything is allocated, so an absurd count is a message, not an
  // allocation failure; a sparse-only accessor is bounded by kMaxSparseOnlyCount.
  ViewBytes view;
  size_t stride = elementBytes;
  if (acc.bufferView >= 0) {
    view = viewBytes(context_, acc.bufferView, where);
    stride = view.stride ? view.stride : elementBytes;
    if (stride < elementBytes) {
      context_.fail(where + ": bufferView " + std::to_string(acc.bufferView) + " byteStride " +
                    std::to_string(stride) + " is smaller than one element (" + std::to_string(elementBytes) +
                    " bytes)");
    }
    // Last byte read: byteOffset + stride * (count - 1) + elementBytes (spec 3.6.2.4), checked
    // without overflow for any count.
    const bool fits = acc.count == 0 ||
                      (acc.byteOffset <= view.length && elementBytes <= view.length - acc.byteOffset &&
                       acc.count - 1 <= (view.length - acc.byteOffset - elementBytes) / stride);
    if (!fits) {
      context_.fail(where + ": " + std::to_string(acc.count) + " elements from byte " + std::to_string(acc.byteOffset) +
                    " (stride " + std::to_string(stride) + ") do not fit: bufferView " +
                    std::to_string(acc.bufferView) + " has " + std::to_string(view.length) + " bytes");
    }
  } else {
    constexpr size_t kMaxSparseOnlyCount = size_t(1) << 28;
    if (acc.count > kMaxSparseOnlyCount) {
      context_.fail(where + ": count " + std::to_string(acc.count) + " without a bufferView exceeds " +
                    std::to_string(kMaxSparseOnlyCount));
    }
  }
  // Decoded as doubles, then kept as floats or 32-bit indices.
  context_.charge(saturatingMul(saturatingMul(acc.count, size_t(comps)), sizeof(double) + sizeof(float)), where);
  std::vector<double> out(acc.count * size_t(comps), 0.0);
  if (acc.bufferView >= 0) {
    for (size_t i = 0; i < acc.count; ++i) {
      const uint8_t* element = view.data + acc.byteOffset + i * stride;
      for (int c = 0; c < comps; ++c) {
        out[i * size_t(comps) + size_t(c)] = readComponent(element + size_t(c) * size_t(compBytes), acc.componentType, normalized);
      }
    }
  }

  // Sparse substitution (spec 3.6.2.3): indices name the elements replaced by values.
  if (acc.sparse.isSparse) {
    const size_t n = size_t(std::max(acc.sparse.count, 0));
    if (n > acc.count) {
      context_.fail(where + ": sparse count " + std::to_string(n) + " exceeds the accessor count " +
                    std::to_string(acc.count));
    }
    const int indexType = acc.sparse.indices.componentType;
    const int indexBytes = componentBytes(indexType);
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      context_.fail(where + ": sparse indices have invalid componentType " + std::to_string(indexType));
    }
    ViewBytes indexView = viewBytes(context_, acc.sparse.indices.bufferView, where + " sparse indices");
    ViewBytes valueView = viewBytes(context_, acc.sparse.values.bufferView, where + " sparse values");
    const size_t indexOffset = size_t(std::max(acc.sparse.indices.byteOffset, 0));
    const size_t valueOffset = size_t(std::max(acc.sparse.values.byteOffset, 0));
    if (indexOffset + n * size_t(indexBytes) > indexView.length) {
      context_.fail(where + ": sparse indices exceed bufferView " + std::to_string(acc.sparse.indices.bufferView));
    }
    if (valueOffset + n * elementBytes > valueView.length) {
      context_.fail(where + ": sparse values exceed bufferView " + std::to_string(acc.sparse.values.bufferView));
    }
    for (size_t k = 0; k < n; ++k) {
      const size_t target = size_t(readComponent(indexView.data + indexOffset + k * size_t(indexBytes), indexType, false));
      if (target >= acc.count) {
        context_.fail(where + ": sparse index " + std::to_string(target) + " is out of range (count " +
                      std::to_string(acc.count) + ")");
      }
      const uint8_t* element = valueView.data + valueOffset + k * elementBytes;
      for (int c = 0; c < comps; ++c) {
        out[target * size_t(comps) + size_t(c)] = readComponent(element + size_t(c) * size_t(compBytes), acc.componentType, normalized);
      }
    }
  }
  return out;
}

const FloatAccessor& AccessorReader::floats(int index, const std::string& what) {
  if (auto it = floats_.find(index); it != floats_.end()) return it->second;
  FloatAccessor result;
  std::vector<double> values = decode(index, what, &result.components, /*applyNormalized=*/true);
  result.count = context_.model.accessors[size_t(index)].count;
  result.values.resize(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    float v = float(values[i]);
    if (!std::isfinite(v)) {
      context_.fail(what + ": accessor " + std::to_string(index) + " element " +
                    std::to_string(i / size_t(result.components)) + " is not a finite number (NaN or Inf)");
    }
    result.values[i] = v;
  }
  return floats_.emplace(index, std::move(result)).first->second;
}

const std::vector<uint32_t>& AccessorReader::indices(int index, const std::string& what) {
  if (auto it = indices_.find(index); it != indices_.end()) return it->second;
  int components = 0;
  std::vector<double> values = decode(index, what, &components, /*applyNormalized=*/false);
  const auto& acc = context_.model.accessors[size_t(index)];
  if (components != 1 || (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                          acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                          acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
    context_.fail(what + ": accessor " + std::to_string(index) +
                  " must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT to hold indices");
  }
  std::vector<uint32_t> out(values.size());
  for (size_t i = 0; i < values.size(); ++i) out[i] = uint32_t(values[i]);
  return indices_.emplace(index, std::move(out)).first->second;
}

}  // namespace pr::scene::gltf
