// The irradiance cache's pre-pass, run through the render's own tracer (rt::PrePassTracer) as
// two programs: a probe program (one pixel per image pixel: its camera ray followed through
// ideal mirrors and glass to the first surface with a diffuse part, and on through that surface
// when it is mostly glass, each such surface a probe) and, per level, a gather
// program (one pixel per new record: its final-gather rays, final_gather.h, whose hits read the
// global map where the tracer shades them). Record placement is deterministic: the probes are
// taken on grids of stride 16, 8, 4, 2 and 1 pixels; at each level the probes no record of the
// earlier levels covers gather a new record, in parallel, and the records are inserted in pixel
// order on the controlling thread - a record's placement depends only on coarser levels.
// Probe hits and gather samples travel to PE 0 as counted messages; each level's chosen probes
// and new records are broadcast to every other PE.
#pragma once

#include <cstdint>

#include "common/scene/camera.h"
#include "common/scene/scene.h"
#include "photonmap/final_gather.h"
#include "photonmap/irradiance_cache.h"

namespace pr::par {
class Runtime;
}
namespace pr::rt {
class PrePassTracer;
}

namespace pr::pm {

struct CachePassOptions {
  GatherOptions gather;      // rays per record, the global map's lookup, seed
  float accuracy = 0.25f;    // Ward's a
  int maxDepth = 8;          // mirror and glass bounces a probe follows
  rt::IntegratorOptions camera;  // the render's options (seed, effects): probe rays are its sample 0
};

// The cache for the image (width x height through `camera`). Counters IrradianceCache/probes
// and IrradianceCache/gather_hits (per PE that shaded them), IrradianceCache/records (PE 0).
IrradianceCache buildIrradianceCache(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                     const KdTree& global, const CachePassOptions& options, rt::PrePassTracer& tracer,
                                     par::Runtime& rt);

}  // namespace pr::pm
