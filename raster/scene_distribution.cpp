// The scene's distribution to the raster PEs: sizes, shares and the first-frame records.
#include "raster/scene_distribution.h"

#include <numeric>
#include <stdexcept>
#include <string>

#include "common/parallel/channel.h"

namespace pr::raster {

uint64_t geometryBytes(const scene::Scene& s) {
  return s.geometryBytes();
}

uint64_t shadingDataBytes(const scene::Scene& s) {
  const uint64_t all = s.memoryBytes(), geometry = geometryBytes(s);
  return all > geometry ? all - geometry : 0;
}

std::pair<uint32_t, uint32_t> primitiveShare(uint32_t total, int pe, int pes) {
  return {static_cast<uint32_t>(uint64_t(total) * pe / pes), static_cast<uint32_t>(uint64_t(total) * (pe + 1) / pes)};
}

bool SceneDistribution::firstFrame(const scene::Scene& s, const par::Runtime& rt) {
  // A fresh runtime has recorded no stage yet (it may sit where an earlier one was).
  const bool first = scene_ != &s || runtime_ != &rt || triangles_ != s.triangles.size() || rt.record().stages.empty();
  scene_ = &s;
  runtime_ = &rt;
  triangles_ = s.triangles.size();
  return first;
}

void distributeReplicated(par::Runtime& rt, const scene::Scene& s) {
  rt.recordBroadcast(s.memoryBytes());
  for (int p = 0; p < rt.pes(); ++p) {
    rt.addCounter("Scene/geometry_bytes_held", p, double(geometryBytes(s)));
    rt.addCounter("Scene/primitives_held", p, double(s.triangles.size()));
  }
}

PrimitiveRecord primitiveRecord(const scene::Scene& s, uint32_t id) {
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

void installPrimitive(scene::Scene& view, const PrimitiveRecord& r) {
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

void installPrimitives(scene::Scene& view, const PrimitiveBatch& batch) {
  for (size_t i = 0; i < batch.size(); ++i) installPrimitive(view, batch.record(i));
}

std::vector<PrimitiveBatch> distributeShares(par::Runtime& rt, const scene::Scene& s, std::string_view stage) {
  const uint32_t total = static_cast<uint32_t>(s.triangles.size());
  rt.recordBroadcast(shadingDataBytes(s));
  par::Channel<PrimitiveBatch> shares(rt, "scene geometry", par::MessageKind::Data);
  rt.runOnEachPe(stage, [&](par::Pe& pe) {
    if (pe.id() != 0) return;
    for (int p = 1; p < rt.pes(); ++p) {
      const auto [first, end] = primitiveShare(total, p, rt.pes());
      if (end == first) continue;
      PrimitiveBatch share{&s, {}, {}};
      share.ids.resize(end - first);
      std::iota(share.ids.begin(), share.ids.end(), first);
      shares.send(pe, p, std::move(share));
    }
  });
  std::vector<PrimitiveBatch> received(size_t(rt.pes()));
  for (int p = 0; p < rt.pes(); ++p) {
    std::vector<PrimitiveBatch> messages = shares.drain(p);  // one at most
    if (!messages.empty()) received[size_t(p)] = std::move(messages.front());
    const auto [first, end] = primitiveShare(total, p, rt.pes());
    rt.addCounter("Scene/geometry_bytes_held", p, double(uint64_t(end - first) * kPrimitiveBytes));
    rt.addCounter("Scene/primitives_held", p, double(end - first));
  }
  return received;
}

}  // namespace pr::raster

namespace pr::par {

void Wire<raster::PrimitiveBatch>::encode(const raster::PrimitiveBatch& b, WireWriter& w) {
  w.reserve(size(b));
  for (size_t i = 0; i < b.size(); ++i) w.value(b.record(i));
}

raster::PrimitiveBatch Wire<raster::PrimitiveBatch>::decode(WireReader& r) {
  raster::PrimitiveBatch b;
  b.records = r.elements<raster::PrimitiveRecord>();
  return b;
}

}  // namespace pr::par
