// The registry of ray-tracer partitions: one line per partition (name, description, factory).
// Feeds `parrender render -m`, its --help text, validation and the equivalence tests.
#include <string>

#include "common/util/error.h"
#include "raytrace/partition/partition.h"

namespace pr::rt {

const std::vector<PartitionInfo>& partitions() {
  static const std::vector<PartitionInfo> kPartitions = {
      {"sequential", "one PE, one message queue, the whole scene (the reference)", makeSequentialPartition},
      {"image-space", "PEs render image tiles as tasks; world model (scene broadcast to every PE)", makeImageSpacePartition},
      {"object-space", "voxels of a cost-balanced kd split own their geometry; rays travel between owners as messages", makeObjectSpacePartition},
      {"object", "objects balanced by triangle count own their geometry; rays query the owners they can reach, hits return", makeObjectPartition},
  };
  return kPartitions;
}

bool isPartition(std::string_view name) {
  for (const PartitionInfo& p : partitions())
    if (p.name == name) return true;
  return false;
}

std::unique_ptr<Partition> makePartition(std::string_view name) {
  std::string names;
  for (const PartitionInfo& p : partitions()) {
    if (p.name == name) return p.make();
    names += (names.empty() ? "" : ", ") + std::string(p.name);
  }
  throw InputError("unknown ray-tracing method '" + std::string(name) + "' (expected one of: " + names + ")");
}

TraceResult renderRays(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                       const TraceOptions& options, std::string_view partition, par::Runtime& rt) {
  auto range = [](const char* what, long value, long lo, long hi) {
    if (value < lo || value > hi)
      throw InputError(std::string(what) + " " + std::to_string(value) + " is out of range [" + std::to_string(lo) +
                       ", " + std::to_string(hi) + "]");
  };
  range("image width", width, 1, 1 << 15);
  range("image height", height, 1, 1 << 15);
  range("spp", options.integrator.spp, 1, kMaxSpp);
  range("max depth", options.integrator.maxDepth, 1, kMaxDepthLimit);
  range("tile size", options.tileSizePx, 1, 4096);
  if (scene.triangles.empty()) throw InputError("scene " + scene.source.string() + " has no triangles to ray trace");
  std::unique_ptr<Partition> p = makePartition(partition);
  return p->render(TraceJob{scene, camera, width, height, options}, rt);
}

}  // namespace pr::rt
