// The world-model message loop (sequential and image-space tracers) and IntegratorBase, which
// instantiates it once per concrete integrator: a tracer makes one virtual call per task
// (Integrator::traceToCompletion) and the loop inside calls the concrete, final shade
// directly — no virtual call per ray (STYLE.md section 3). An integrator from another library
// (photonmap) derives from IntegratorBase<Self> the same way and gets the same loop.
#pragma once

#include <type_traits>
#include <vector>

#include "raytrace/core/bvh.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/film.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/integrators/trace_stats.h"

namespace pr::rt {

// Traces every message in `queue` and every message shading spawns until none is left,
// against the full BVH, on the calling PE. Adds rays traced by kind to `stats`. The queue is
// used as a stack (depth first), which bounds its length; order does not change the image
// (fixed-point film). Shader: a concrete integrator (shade, miss).
template <class Shader>
void traceLoop(const Shader& integrator, const scene::Scene& scene, const Bvh& bvh, std::vector<RayMessage>& queue,
               Film& film, TraceStats& stats, int pe) {
  Emit emit(film, queue, stats, pe);
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

// Base of every concrete integrator: `class MyIntegrator final : public IntegratorBase<MyIntegrator>`
// with a `shade(...) const override`. Derived must be final so that shade, called on a
// const Derived&, is a direct call.
template <class Derived>
class IntegratorBase : public Integrator {
 public:
  using Integrator::Integrator;

  void traceToCompletion(const Bvh& bvh, std::vector<RayMessage>& queue, Film& film, TraceStats& stats,
                         int pe) const final {
    static_assert(std::is_final_v<Derived>, "a concrete integrator must be final (direct shade calls in the loop)");
    traceLoop(static_cast<const Derived&>(*this), context().scene(), bvh, queue, film, stats, pe);
  }
};

}  // namespace pr::rt
