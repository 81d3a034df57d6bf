// Primitive records and batches: made from a scene, installed into a PE's copy of it, encoded.
#include "common/scene/primitive_batch.h"

#include <stdexcept>
#include <string>

namespace pr::scene {

PrimitiveRecord primitiveRecord(const Scene& s, uint32_t id) {
  PrimitiveRecord r;
  r.id = id;
  r.triangle = s.triangles[id];
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = r.triangle.v[k];
    r.position[k] = s.positions[v];
    if (v < s.normals.size()) r.normal[k] = s.normals[v];
    if (v < s.uvs.size()) r.uv[k] = s.uvs[v];
    if (v < s.colors.size()) r.colour[k] = s.colors[v];
    if (v < s.tangents.size()) r.tangent[k] = s.tangents[v];
  }
  return r;
}

void installPrimitive(Scene& view, const PrimitiveRecord& r) {
  // A message from another rank is checked, not trusted: what it names must exist.
  if (r.id >= view.triangles.size())
    throw std::out_of_range("a primitive message names triangle " + std::to_string(r.id) + " of " +
                            std::to_string(view.triangles.size()));
  view.triangles[r.id] = r.triangle;
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = r.triangle.v[k];
    if (v >= view.positions.size())
      throw std::out_of_range("a primitive message names vertex " + std::to_string(v) + " of " +
                              std::to_string(view.positions.size()));
    view.positions[v] = r.position[k];
    if (v < view.normals.size()) view.normals[v] = r.normal[k];
    if (v < view.uvs.size()) view.uvs[v] = r.uv[k];
    if (v < view.colors.size()) view.colors[v] = r.colour[k];
    if (v < view.tangents.size()) view.tangents[v] = r.tangent[k];
  }
}

PrimitiveRecord PrimitiveBatch::record(size_t i) const {
  return source ? primitiveRecord(*source, ids[i]) : records[i];
}

void installPrimitives(Scene& view, const PrimitiveBatch& batch) {
  for (size_t i = 0; i < batch.size(); ++i) installPrimitive(view, batch.record(i));
}

}  // namespace pr::scene

namespace pr::par {

void Wire<scene::PrimitiveBatch>::encode(const scene::PrimitiveBatch& b, WireWriter& w) {
  w.reserve(size(b));
  for (size_t i = 0; i < b.size(); ++i) w.value(b.record(i));
}

scene::PrimitiveBatch Wire<scene::PrimitiveBatch>::decode(WireReader& r) {
  scene::PrimitiveBatch b;
  b.records = r.elements<scene::PrimitiveRecord>();
  return b;
}

}  // namespace pr::par
