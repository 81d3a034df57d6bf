// The scene's distribution to the raster PEs: sizes, shares and the first-frame records.
#include "raster/scene_distribution.h"

#include <numeric>
#include <string>


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
  rt.recordReplicated(s.memoryBytes());  // across ranks, every rank loaded it
  for (int p = 0; p < rt.pes(); ++p) {
    rt.addCounter("Scene/geometry_bytes_held", p, double(geometryBytes(s)));
    rt.addCounter("Scene/primitives_held", p, double(s.triangles.size()));
  }
}

std::vector<PrimitiveBatch> distributeShares(par::Runtime& rt, const scene::Scene& s, std::string_view stage) {
  const uint32_t total = static_cast<uint32_t>(s.triangles.size());
  rt.recordReplicated(shadingDataBytes(s));  // across ranks, every rank loaded it
  std::vector<PrimitiveBatch> received = scene::sendPrimitiveShares(rt, s, stage, [&](int p) {
    const auto [first, end] = primitiveShare(total, p, rt.pes());
    std::vector<uint32_t> ids(end - first);
    std::iota(ids.begin(), ids.end(), first);
    return ids;
  });
  for (int p = 0; p < rt.pes(); ++p) {
    const auto [first, end] = primitiveShare(total, p, rt.pes());
    rt.addCounter("Scene/geometry_bytes_held", p, double(uint64_t(end - first) * kPrimitiveBytes));
    rt.addCounter("Scene/primitives_held", p, double(end - first));
  }
  return received;
}

}  // namespace pr::raster
