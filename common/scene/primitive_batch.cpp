// Primitive records and batches: made from a scene, installed into a PE's copy of it, encoded.
#include "common/scene/primitive_batch.h"

#include <string>

#include "common/parallel/channel.h"
#include "common/scene/poisoned_view.h"

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
    throw par::WireError("a primitive message names triangle " + std::to_string(r.id) + " of " +
                         std::to_string(view.triangles.size()));
  if (r.triangle.material >= view.materials.size())
    throw par::WireError("a primitive message names material " + std::to_string(r.triangle.material) + " of " +
                         std::to_string(view.materials.size()));
  view.triangles[r.id] = r.triangle;
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = r.triangle.v[k];
    if (v >= view.positions.size())
      throw par::WireError("a primitive message names vertex " + std::to_string(v) + " of " +
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

std::vector<PrimitiveBatch> sendPrimitiveShares(par::Runtime& rt, const Scene& s, std::string_view stage,
                                                const std::function<std::vector<uint32_t>(int)>& held) {
  par::Channel<PrimitiveBatch> shares(rt, "scene geometry", par::MessageKind::Data);
  rt.runOnEachPe(stage, [&](par::Pe& pe) {
    if (pe.id() != 0) return;
    for (int p = 1; p < rt.pes(); ++p) {
      PrimitiveBatch share{&s, held(p), {}};
      if (share.size() > 0) shares.send(pe, p, std::move(share));
    }
  });
  std::vector<PrimitiveBatch> received(size_t(rt.pes()));
  for (int p = 0; p < rt.pes(); ++p)
    for (PrimitiveBatch& m : shares.drain(p)) received[size_t(p)] = std::move(m);  // one at most
  return received;
}

std::unique_ptr<Scene> shareView(const Scene& s, int pe, std::span<const uint32_t> held,
                                 std::span<const uint32_t> alsoHeld, const PrimitiveBatch& received) {
  std::unique_ptr<Scene> view = poisonedView(s, pe == 0 ? held : std::span<const uint32_t>(), alsoHeld);
  installPrimitives(*view, received);
  return view;
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
