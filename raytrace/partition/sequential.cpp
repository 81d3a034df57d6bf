// The sequential tracer: one PE, one message queue, the BVH over the whole scene — the
// reference every parallel partition must reproduce bit for bit, and the place where the
// shared message loop (traceToCompletion) lives. Runs as a single task on the runtime so its
// time is measured like any other method's.
#include <memory>

#include "raytrace/partition/partition.h"

namespace pr::rt {

void traceToCompletion(const scene::Scene& scene, const Bvh& bvh, const Integrator& integrator,
                       std::vector<RayMessage>& queue, Film& film, TraceStats& stats) {
  Emit emit(film, queue);
  while (!queue.empty()) {
    const RayMessage msg = queue.back();
    queue.pop_back();
    if (msg.kind == RayKind::Shadow) {
      ++stats.shadowRays;
      if (!bvh.occluded(msg.ray)) integrator.miss(msg, emit);
      continue;
    }
    ++(msg.kind == RayKind::Camera ? stats.cameraRays : stats.continuationRays);
    Hit hit;
    if (bvh.intersect(msg.ray, hit))
      integrator.shade(makeInteraction(scene, msg.ray, hit), msg, emit);
    else
      integrator.miss(msg, emit);
  }
}

namespace {

class SequentialPartition final : public Partition {
 public:
  std::string_view name() const override { return "sequential"; }

  TraceResult render(const TraceJob& job, par::Runtime& rt) override {
    std::unique_ptr<Bvh> built;
    if (!job.options.worldBvh) built = std::make_unique<Bvh>(job.scene, job.options.bvh);
    const Bvh& bvh = job.options.worldBvh ? *job.options.worldBvh : *built;
    const Integrator integrator(job.scene, job.camera, job.width, job.height, job.options.integrator);
    Film film(job.width, job.height, job.options.integrator.spp);
    TraceCounters counters;
    rt.runStage("trace", par::TaskSet::uniform(1), [&](par::Pe&, par::TaskId) {
      TraceStats stats;
      std::vector<RayMessage> queue;
      // Row by row keeps the queue at one row of camera rays plus one path's messages; the
      // single task reports its progress in rows.
      for (int y = 0; y < job.height; ++y) {
        integrator.cameraRays(PixelRect{0, y, job.width, y + 1}, queue);
        traceToCompletion(job.scene, bvh, integrator, queue, film, stats);
        if (job.options.progress) job.options.progress(y + 1, job.height);
      }
      counters.add(stats);
    });
    return TraceResult{film.toImage(), counters.stats(), 1};
  }
};

}  // namespace

std::unique_ptr<Partition> makeSequentialPartition() { return std::make_unique<SequentialPartition>(); }

}  // namespace pr::rt
