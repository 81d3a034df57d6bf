// The scene's distribution to the raster PEs: sizes, shares and the first-frame records.
#include "raster/scene_distribution.h"

#include <numeric>
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
