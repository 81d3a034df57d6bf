// The registry of ray-tracer partitions: one line per partition (name, description, factory).
// Feeds `parrender render -m`, its --help text, validation and the equivalence tests.
#include <algorithm>
#include <memory>
#include <string>

#include "common/util/error.h"
#include "raytrace/partition/film_assembly.h"
#include "raytrace/partition/partition.h"

namespace pr::rt {

const PartitionRegistry& partitions() {
  static const PartitionRegistry kPartitions(
      "ray-tracing method",
      {
          {"sequential", "one PE, one message queue, the whole scene (the reference)", makeSequentialPartition},
          {"image-space", "PEs render image tiles as tasks; world model (scene broadcast to every PE)", makeImageSpacePartition},
          {"image-space-cached", "image tiles as tasks; geometry items owned by PEs, fetched on demand into an LRU cache (data manager)", makeCachedImageSpacePartition},
          {"object-space", "voxels of a cost-balanced kd split own their geometry; rays travel between owners as messages", makeObjectSpacePartition},
          {"object", "objects balanced by triangle count own their geometry; rays query the owners they can reach, hits return", makeObjectPartition},
      });
  return kPartitions;
}

bool isPartition(std::string_view name) { return partitions().contains(name); }

std::unique_ptr<Partition> makePartition(std::string_view name) { return partitions().find(name).make(); }

TraceStats recordRayCounters(par::Runtime& rt, const std::vector<TraceStats>& perPe) {
  TraceStats sum;
  for (size_t p = 0; p < perPe.size(); ++p) {
    for (const TraceCounter& c : kTraceCounters) rt.addCounter(c.name, int(p), double(perPe[p].*c.field));
    sum += perPe[p];
  }
  return sum;
}

namespace {

// Runs an integrator's pre-pass programs through the render's partition (PrePassTracer): each
// one a job over the program's virtual image, its film not assembled, sharing the render's
// world BVH where the partition holds one (the partitioned tracers distribute their geometry
// afresh for each program, and count it).
class PartitionPrePass final : public PrePassTracer {
 public:
  PartitionPrePass(const TraceJob& render, std::string_view partition, par::Runtime& rt)
      : render_(render), partition_(partition), rt_(rt) {}

  void trace(const std::shared_ptr<const Integrator>& program, int tileSizePx) override {
    const IntegratorContext& c = program->context();
    TraceJob job{render_.scene, render_.camera, c.width(), c.height(), render_.options};
    job.options.tileSizePx = std::max(1, tileSizePx);
    job.options.adaptive = false;
    job.options.progress = {};
    job.integrator = program;
    job.assembleImage = false;
    job.stagePrefix = std::string(program->name()) + " ";
    // The first job of the render sends the PEs what they keep (the scene, the world BVH, the
    // shading data); the later ones find it there.
    job.sceneResident = traced_;
    makePartition(partition_)->render(job, rt_);
    traced_ = true;
  }
  bool traced() const { return traced_; }

 private:
  const TraceJob& render_;
  std::string partition_;
  par::Runtime& rt_;
  bool traced_ = false;
};

}  // namespace

PreparedRays prepareRays(const TraceJob& job, std::string_view partition, par::Runtime& rt) {
  auto range = [](const char* what, long value, long lo, long hi) {
    if (value < lo || value > hi)
      throw InputError(std::string(what) + " " + std::to_string(value) + " is out of range [" + std::to_string(lo) +
                       ", " + std::to_string(hi) + "]");
  };
  const IntegratorOptions& io = job.integrator ? job.integrator->options() : job.options.integrator;
  range("image width", job.width, 1, 1 << 15);
  range("image height", job.height, 1, 1 << 15);
  range("spp", io.spp, 1, kMaxSpp);
  range("max depth", io.maxDepth, 1, kMaxDepthLimit);
  range("tile size", job.options.tileSizePx, 1, 4096);
  if (job.scene.triangles.empty())
    throw InputError("scene " + job.scene.source.string() + " has no triangles to ray trace");
  checkBvhLimit("scene " + job.scene.source.string(), job.scene.triangles.size());
  std::unique_ptr<Partition> p = makePartition(partition);
  // Every BVH a partition builds over this scene tests its alpha-cut surfaces.
  PreparedRays prepared{job, nullptr};
  TraceJob& main = prepared.job;
  if (!main.options.bvh.alpha) main.options.bvh.alpha = AlphaTest::forScene(job.scene);
  if (!job.integrator || !job.integrator->hasPrePass()) return prepared;
  // The integrator's pre-pass runs through this same tracer; a world-model tracer builds its
  // BVH once for the pre-pass's programs and the render.
  if (p->holdsWorldModel() && !job.options.worldBvh) {
    rt.runOncePerRank("build", [&](par::Pe&) { prepared.worldBvh = std::make_unique<Bvh>(job.scene, main.options.bvh); });
    main.options.worldBvh = prepared.worldBvh.get();
  }
  PartitionPrePass tracer(main, partition, rt);
  job.integrator->prePass(tracer, rt);
  main.sceneResident = tracer.traced();
  return prepared;
}

TraceResult renderRays(const TraceJob& job, std::string_view partition, par::Runtime& rt) {
  const PreparedRays prepared = prepareRays(job, partition, rt);
  return makePartition(partition)->render(prepared.job, rt);
}

TraceResult renderRays(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                       const TraceOptions& options, std::string_view partition, par::Runtime& rt) {
  return renderRays(TraceJob{scene, camera, width, height, options}, partition, rt);
}

}  // namespace pr::rt
