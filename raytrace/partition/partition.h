// Partition: how a ray tracer splits work and data over the PEs of par::Runtime — the seed's
// classification (section 5.1.2): image-space (tiles; world model), object-space (voxels own
// geometry; rays travel as messages) and object partitioning (objects own geometry; rays
// visit owners). All of them move the same RayMessages through the same Integrator and the
// same Bvh queries, so they give the same image bit for bit; a Partition decides only where a
// message is traced. One implementation per file beside this one, one line in registry.cpp.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/image/image.h"
#include "common/parallel/runtime.h"
#include "common/scene/camera.h"
#include "common/scene/scene.h"
#include "common/util/registry.h"
#include "raytrace/core/bvh.h"
#include "raytrace/integrators/film.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/integrators/trace_stats.h"

namespace pr::rt {

inline constexpr int kDefaultRayBatch = 64;
inline constexpr int kMaxRayBatch = 65536;
inline constexpr std::size_t kDefaultCacheBytes = std::size_t{64} << 20;

struct TraceOptions {
  IntegratorOptions integrator;
  int tileSizePx = 16;    // image-space: tile edge in pixels (the task granularity)
  bool adaptive = false;  // image-space: split tiles whose estimated cost is far above the mean
  // object-space and object partitioning: rays (queries, replies) per message to one PE; a
  // partial batch is sent when its PE runs dry (common/parallel/batched_channel.h).
  int rayBatch = kDefaultRayBatch;
  // image-space-cached: each PE's cache of other PEs' geometry items, in bytes (LRU).
  std::size_t cacheBytes = kDefaultCacheBytes;
  // image-space-cached: a simulated one-way latency of every data message, in seconds, and
  // whether a ray that waits for an item yields to the tile's other rays (latency hiding, seed
  // section 4.5.2) instead of the PE waiting for the reply.
  double dataLatencySeconds = 0.0;
  bool hideLatency = true;
  // image-space-cached: what a PE prefetches before a tile (cached_image_space.cpp): the items
  // its own finished neighbouring tiles used, falling back to the camera rays' first items
  // (profile); the camera rays' first items only (camera); nothing (none).
  enum class Prefetch { Profile, CameraRays, None };
  Prefetch prefetch = Prefetch::Profile;
  BvhBuildOptions bvh;
  // A BVH already built over the whole scene with these options, reused by the world-model
  // tracers (sequential, image-space) instead of building one; nullptr = build it.
  const Bvh* worldBvh = nullptr;
  // A check of the partitioned tracers (object-space, object partitioning, image-space-cached),
  // for tests in one process: each PE shades from its own copy of the scene in which the
  // vertices of every triangle it was not sent (and that is no emitter, which every PE holds a
  // counted copy of) are NaN, so reading another PE's geometry outside a message changes the
  // image. Costs a scene copy per PE; across ranks every PE reads such a copy anyway.
  bool poisonForeignGeometry = false;
  // Called after each task with (tasks done, tasks total), from the PE that ran it (a
  // single-task tracer may report finer units, e.g. rows): must be thread-safe and cheap.
  // Empty = no progress reports.
  std::function<void(int64_t, int64_t)> progress;
};

// The rays each PE traced, by kind, put in the run record as the per-PE counters Rays/camera,
// Rays/continuation and Rays/shadow, and the work the RenderPlan skipped as Plan/... counters
// (Plan/shadow_tests_skipped, ...; trace_stats.h) (the only way the figures leave a tracer, STYLE.md
// section 4); returns their sum over PEs for TraceResult::rays. On the controlling thread,
// after the tracer's last stage.
TraceStats recordRayCounters(par::Runtime& rt, const std::vector<TraceStats>& perPe);

// Per-PE ray counts written during a stage, each PE its own (padded against false sharing).
class PerPeTraceStats {
 public:
  explicit PerPeTraceStats(int pes) : stats_(size_t(pes)) {}
  TraceStats& of(int pe) { return stats_[size_t(pe)].stats; }
  std::vector<TraceStats> values() const {
    std::vector<TraceStats> out;
    for (const Padded& p : stats_) out.push_back(p.stats);
    return out;
  }

 private:
  struct alignas(64) Padded {
    TraceStats stats;
  };
  std::vector<Padded> stats_;
};

struct TraceResult {
  image::Image image;
  TraceStats rays;  // the sum of the run record's Rays/ counters this render added
  size_t tasks = 0;  // tasks of the trace stage
};

// One render: the scene, its camera, the image size, the options and the integrator.
struct TraceJob {
  const scene::Scene& scene;
  const scene::Camera& camera;
  int width = 0, height = 0;
  TraceOptions options;
  // Ready built by the caller for this scene, camera and size, e.g. from the program's
  // integrator registry (tools/integrators.h); its options() (spp, depth, seed) are the
  // render's, options.integrator is then unused. nullptr: the built-in integrator that
  // options.integrator.kind names, built by the partition.
  std::shared_ptr<const Integrator> integrator = nullptr;
  // False for a pre-pass program (PrePassTracer): it adds no radiance (its results are its own,
  // per PE), so its film is one pixel, not assembled on PE 0, and it gets no cost pre-pass
  // (which would run the program's side effects twice); the image is then 1 x 1 and black.
  bool assembleImage = true;
  // The film a tracer shades into for this job: the image's, or one pixel for a program.
  int filmWidth() const { return assembleImage ? width : 1; }
  int filmHeight() const { return assembleImage ? height : 1; }
  // The PEs hold the scene's replicated data already (the world model's scene and BVH, the
  // partitioned tracers' shading data, emitters and directory): its broadcast is not counted
  // again (the second and later jobs of one render: pre-pass programs and the render).
  bool sceneResident = false;
  // Put before the tracer's stage names ("build", "trace"), so that a pre-pass program's
  // stages are told apart from the render's in the run record ("photon-pass trace").
  std::string stagePrefix{};
  std::string stage(std::string_view name) const { return stagePrefix + std::string(name); }
};

// The integrator a partition renders job with: job.integrator, or the built-in default.
// Called once per render on the controlling thread.
std::shared_ptr<const Integrator> jobIntegrator(const TraceJob& job);

class Partition {
 public:
  virtual ~Partition() = default;
  virtual std::string_view name() const = 0;
  // Whether every PE reads the whole scene and one BVH over it (world model, DESIGN.md rule 1):
  // such a tracer shares one BVH between an integrator's pre-pass and its render.
  virtual bool holdsWorldModel() const { return false; }
  // Whether its stages run as SPMD code on a runtime of several ranks (runtime.h): the code
  // between its stages reads only what its rank holds.
  virtual bool runsAcrossRanks() const { return false; }
  // Runs the render on rt's PEs (stages recorded in rt.record()). Called from the
  // controlling thread.
  virtual TraceResult render(const TraceJob& job, par::Runtime& rt) = 0;
};

// Registry: name -> factory -> description (registry.cpp); feeds --help, validation, reports.
using PartitionInfo = RegistryEntry<std::unique_ptr<Partition> (*)()>;
using PartitionRegistry = Registry<std::unique_ptr<Partition> (*)()>;
const PartitionRegistry& partitions();
bool isPartition(std::string_view name);
// Throws pr::InputError naming the unknown partition and listing the valid ones.
std::unique_ptr<Partition> makePartition(std::string_view name);

// A render made ready for its tracer: validated (size, options), its BVH options set for the
// scene, and the integrator's pre-passes run through the named partition on rt (for a
// world-model partition, over a world BVH built here unless the job brought one, then kept in
// worldBvh and named by job.options.worldBvh). Throws pr::InputError for a bad job.
struct PreparedRays {
  TraceJob job;
  std::unique_ptr<Bvh> worldBvh;
};
PreparedRays prepareRays(const TraceJob& job, std::string_view partition, par::Runtime& rt);

// Validates the job (size, options) and runs the named partition (prepareRays, then render).
TraceResult renderRays(const TraceJob& job, std::string_view partition, par::Runtime& rt);
// The same for a job with the built-in integrator options.integrator.kind names.
TraceResult renderRays(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                       const TraceOptions& options, std::string_view partition, par::Runtime& rt);

// Factories, one per partition file.
std::unique_ptr<Partition> makeSequentialPartition();
std::unique_ptr<Partition> makeImageSpacePartition();
std::unique_ptr<Partition> makeCachedImageSpacePartition();
std::unique_ptr<Partition> makeObjectSpacePartition();  // object_space.cpp
std::unique_ptr<Partition> makeObjectPartition();       // object_partition.cpp

}  // namespace pr::rt
