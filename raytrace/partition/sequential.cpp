// The sequential tracer: one PE, one message queue, the BVH over the whole scene — the
// reference every parallel partition must reproduce bit for bit — and jobIntegrator, which
// every partition gets its integrator from. Runs as a single task on the runtime so its time
// is measured like any other method's.
#include <memory>

#include "common/util/error.h"
#include "raytrace/partition/partition.h"

namespace pr::rt {

std::shared_ptr<const Integrator> jobIntegrator(const TraceJob& job) {
  if (job.integrator) {
    const IntegratorContext& ctx = job.integrator->context();
    PR_CHECK(&ctx.scene() == &job.scene && ctx.width() == job.width && ctx.height() == job.height,
             "the job's integrator was built for another scene or image size");
    return job.integrator;
  }
  return makeBuiltinIntegrator(job.options.integrator.kind,
                               IntegratorSetup{job.scene, job.camera, job.width, job.height, job.options.integrator});
}

namespace {

class SequentialPartition final : public Partition {
 public:
  std::string_view name() const override { return "sequential"; }
  bool holdsWorldModel() const override { return true; }

  TraceResult render(const TraceJob& job, par::Runtime& rt) override {
    // The BVH build is a stage of its own, timed like every tracer's build (Ts includes it).
    std::unique_ptr<Bvh> built;
    if (!job.options.worldBvh)
      rt.runStage(job.stage("build"), par::TaskSet::uniform(1), [&](par::Pe&, par::TaskId) {
        built = std::make_unique<Bvh>(job.scene, job.options.bvh);
      });
    const Bvh& bvh = job.options.worldBvh ? *job.options.worldBvh : *built;
    const std::shared_ptr<const Integrator> shared = jobIntegrator(job);
    const Integrator& integrator = *shared;
    Film film(job.filmWidth(), job.filmHeight(), integrator.options().spp);
    PerPeTraceStats counters(rt.pes());
    rt.runStage(job.stage("trace"), par::TaskSet::uniform(1), [&](par::Pe& pe, par::TaskId) {
      TraceStats& stats = counters.of(pe.id());
      std::vector<RayMessage> queue;
      // Row by row keeps the queue at one row of camera rays plus one path's messages; the
      // single task reports its progress in rows.
      for (int y = 0; y < job.height; ++y) {
        integrator.cameraRays(PixelRect{0, y, job.width, y + 1}, queue);
        integrator.traceToCompletion(bvh, queue, film, stats, pe.id());
        if (job.options.progress) job.options.progress(y + 1, job.height);
      }
    });
    return TraceResult{film.toImage(), recordRayCounters(rt, counters.values()), 1};
  }
};

}  // namespace

std::unique_ptr<Partition> makeSequentialPartition() { return std::make_unique<SequentialPartition>(); }

}  // namespace pr::rt
