// What the two data-partitioned tracers (object-space, object partitioning) share besides the
// integrator and the BVH: the figures they report beyond the run record (geometry held per
// PE, messages by kind), the camera-ray tasks (image tiles whose rays are sent to owners), and
// the size of the shading data every PE keeps a copy of (materials, textures, lights).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <memory>
#include <string_view>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/parallel/task.h"
#include "common/parallel/wire.h"
#include "common/util/error.h"
#include "common/scene/poisoned_view.h"
#include "common/scene/primitive_batch.h"
#include "common/scene/scene.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/partition/partition.h"

namespace pr::rt {

// What a partitioned tracer holds on each PE, gathered after its build, for the run record.
struct PartitionHoldings {
  std::vector<uint64_t> geometryBytes;    // per PE: its BVHs plus its triangles' vertex data
  std::vector<uint64_t> triangles;        // per PE: triangles held (straddlers counted per holder)
  std::vector<uint64_t> partitionsOwned;  // per PE: voxels or object pieces
};

// Puts the holdings in the run record as the per-PE counters Partition/geometry_bytes,
// Partition/triangles_held and Partition/partitions_owned: the only way these figures leave
// the tracer (STYLE.md section 4); render summaries, --metrics JSON and tests read the record.
inline void recordPartitionHoldings(const PartitionHoldings& h, par::Runtime& rt) {
  for (int p = 0; p < rt.pes(); ++p) {
    rt.addCounter("Partition/geometry_bytes", p, double(h.geometryBytes[size_t(p)]));
    rt.addCounter("Partition/triangles_held", p, double(h.triangles[size_t(p)]));
    rt.addCounter("Partition/partitions_owned", p, double(h.partitionsOwned[size_t(p)]));
  }
}

// Bytes a PE holds per triangle besides its BVH: the index triple and material, and the
// vertex data shading reads at a hit (position, normal, uv of three vertices).
inline constexpr uint64_t kTriangleVertexBytes =
    sizeof(scene::Triangle) + 3 * (2 * sizeof(glm::vec3) + sizeof(glm::vec2));

// The replicated, read-only part of the scene every PE shades with: everything but the
// geometry (vertices, triangles, objects), counted as one broadcast per PE.
inline uint64_t shadingDataBytes(const scene::Scene& s) {
  const uint64_t geometry = s.geometryBytes();
  const uint64_t all = s.memoryBytes();
  return all > geometry ? all - geometry : 0;
}

// The emitters, replicated on every PE: area-light sampling on whichever PE shades reads the
// emissive triangles' vertices and the sampler's tables, so a partitioned tracer sends every
// PE a copy of them, counted in its broadcast (and reported as Partition/emitter_bytes).
inline uint64_t emitterBytes(const LightSampler& lights) {
  return lights.emitters().size() * kTriangleVertexBytes + lights.tableBytes();
}

// Counts what every PE of a partitioned tracer holds a copy of, one broadcast per PE, called
// between stages, before the trace stage. Unless the scene is resident from an earlier trace:
// the shading data and the emitters, with madeByEveryRank bytes of routing data every rank
// derives itself (an item directory), from the scene every rank loads (Runtime::recordReplicated:
// across ranks each rank made its own). At every trace: sharedBytes that PE 0 made and shared
// (the encoded voxel split or piece assignment, shareEncodedFromRank0; between ranks it
// travelled, booked there, and each rank's other PEs read it: recordBroadcastWithinRanks).
inline void recordReplicatedData(par::Runtime& rt, const TraceJob& job, const LightSampler& lights,
                                 uint64_t madeByEveryRank, uint64_t sharedBytes) {
  if (!job.sceneResident) {
    const uint64_t emitters = emitterBytes(lights);
    for (int p = 0; p < rt.pes(); ++p) rt.addCounter("Partition/emitter_bytes", p, double(emitters));
    rt.recordReplicated(shadingDataBytes(job.scene) + emitters + madeByEveryRank);
  }
  if (sharedBytes > 0) rt.recordBroadcastWithinRanks(sharedBytes);
}

// Counts the rays a camera-ray task starts by kind, as the world-model loop counts the rays it
// traces: camera rays, or a pre-pass program's own start rays (photons, gather rays) as
// continuations.
inline void countStartRays(TraceStats& stats, std::span<const RayMessage> rays) {
  for (const RayMessage& m : rays)
    ++(m.kind == RayKind::Camera ? stats.cameraRays : m.kind == RayKind::Shadow ? stats.shadowRays : stats.continuationRays);
}

// The scene a PE shades and builds from: the shared one, or a view of its own, in which every
// vertex but the emitters' (replicated) and those of the triangles it holds is NaN. A PE has
// its own view across ranks (every rank loaded the scene, but a PE reads only its share) and
// under the poison check of the tests; PE 0 keeps its share from the scene it loaded, every
// other PE installs the share PE 0 sent it (scene::sendPrimitiveShares, scene::shareView), so
// a read of geometry that did not arrive as a message shows in the image.
class SceneViews {
 public:
  SceneViews(const TraceJob& job, const par::Runtime& rt)
      : job_(job), views_(job.options.poisonForeignGeometry || rt.ranks() > 1 ? rt.pes() : 0) {}
  // On PE p, in its build (a stage, or the trace stage's set-up): its view, from the triangles
  // it holds and the share it received.
  void build(int p, std::span<const uint32_t> held, const LightSampler& lights, const scene::PrimitiveBatch& received) {
    if (!views_.empty()) views_[size_t(p)] = scene::shareView(job_.scene, p, held, lights.emitters(), received);
  }
  const scene::Scene& of(int p) const { return views_.empty() ? job_.scene : *views_[size_t(p)]; }

 private:
  const TraceJob& job_;
  std::vector<std::unique_ptr<scene::Scene>> views_;
};

// Throws pr::InputError for a ray batch size outside [1, kMaxRayBatch].
inline void checkRayBatch(const TraceOptions& options, std::string_view method) {
  if (options.rayBatch < 1 || options.rayBatch > kMaxRayBatch)
    throw InputError(std::string(method) + ": ray batch of " + std::to_string(options.rayBatch) +
                     " requested, expected 1 to " + std::to_string(kMaxRayBatch));
}

// Image tiles of tileSizePx, row-major: the camera-ray tasks of the partitioned tracers.
inline std::vector<PixelRect> cameraTiles(int width, int height, int tileSizePx) {
  std::vector<PixelRect> tiles;
  for (int y = 0; y < height; y += tileSizePx)
    for (int x = 0; x < width; x += tileSizePx)
      tiles.push_back({x, y, std::min(width, x + tileSizePx), std::min(height, y + tileSizePx)});
  return tiles;
}

// One film per PE: shading adds to the film of the PE that shades (no shared writes); the
// films go to the assembler at the end (film_assembly.h).
// Across ranks only this rank's PEs and the assembler (`assembler`, whose film is the image on
// rank 0 and a place for the render's result on the others) have one; the rest are null.
inline std::vector<std::unique_ptr<Film>> makeFilms(const TraceJob& job, const par::Runtime& rt, int spp, int assembler) {
  std::vector<std::unique_ptr<Film>> films(size_t(rt.pes()));
  for (int p = 0; p < rt.pes(); ++p)
    if (rt.isLocal(p) || p == assembler) films[size_t(p)] = std::make_unique<Film>(job.filmWidth(), job.filmHeight(), spp);
  return films;
}

// The cost pre-pass of the tile tracers (image-space, image-space-cached): one pixel in
// kCostPrePassStride x kCostPrePassStride (1/16 of the pixels), one sample each. Rays traced
// per tile is the estimate, a pure count, so the estimates (and any schedule built on them)
// do not depend on timing.
constexpr int kCostPrePassStride = 4;
// Rays traced for `sampled` pixels of rect, scaled to its pixel count; at least 1.
inline double tileCostEstimate(uint64_t raysTraced, const PixelRect& rect, int64_t sampled) {
  const double cost = sampled > 0 ? double(raysTraced) * double(rect.pixels()) / double(sampled) : 1.0;
  return std::max(cost, 1.0);
}

// Whether the tiles get preferred PEs (tile_affinity.h): only with another PE to prefer, and
// only for image tiles (a pre-pass program's tasks start no camera rays).
inline bool wantsTileAffinity(const TraceJob& job, int pes) { return job.assembleImage && pes > 1; }

// The tasks of the camera-ray tiles; preferred: per tile, the PE holding what its rays need
// (tile_affinity.h), or empty when none is known.
inline par::TaskSet tileTaskSet(const std::vector<PixelRect>& tiles, int tileSizePx, std::span<const int> preferred = {}) {
  PR_CHECK(preferred.empty() || preferred.size() == tiles.size(), "tileTaskSet: one preferred PE per tile");
  par::TaskSet set;
  for (size_t t = 0; t < tiles.size(); ++t) {
    const PixelRect& r = tiles[t];
    set.tasks.push_back({double(r.pixels()), float(r.x0 + r.x1) * 0.5f / float(tileSizePx),
                         float(r.y0 + r.y1) * 0.5f / float(tileSizePx), preferred.empty() ? -1 : preferred[t]});
  }
  return set;
}

}  // namespace pr::rt
