// The object-space tracer. Stage "build": each owner's voxels get a BVH over the triangles
// they hold. Stage "trace": image tiles are tasks that make camera rays; a ray is traced on
// the PE owning the voxel it is in, and sent (a TravellingRay in a batch on the "rays"
// BatchedChannel) to the owner of the next voxel along it when it leaves without a hit; the
// owner resumes the walk at that voxel. A voxel accepts only a
// hit up to the end of the ray's span in it, so the first voxel that reports a hit reports the
// ray's closest hit, the same one (bit for bit) as the BVH over the whole scene. Shadow rays
// stop at the first voxel that reports any occluder. Shading and spawning happen on the PE
// that found the hit; new rays start from there. The stage ends when no tile, ray or message
// is left (termination.h).
#include "raytrace/partition/object_space.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "common/parallel/batched_channel.h"
#include "raytrace/partition/film_assembly.h"
#include "common/util/error.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/voxel_split.h"

namespace pr::rt {
namespace {

constexpr int kMaxVoxelsPerPe = 64;
constexpr int kMaxVoxels = 4096;  // VoxelSplit's limit

// k·P voxels, k lowered where k·P would pass the split's limit (P up to 4096 PEs).
int voxelCount(int voxelsPerPe, int pes) { return pes * std::max(1, std::min(voxelsPerPe, kMaxVoxels / pes)); }

// A ray on its way to the owner of the next voxel along it: the message with its path state,
// and where the walk through the voxels resumes (the voxel and the ray parameter at which the
// ray enters it), so the owner continues the walk instead of restarting it from the origin.
struct TravellingRay {
  RayMessage message;
  float tEnter = 0.0f;
  uint32_t voxel = kStartVoxel;  // kStartVoxel: a new ray, traced from its first voxel
  static constexpr uint32_t kStartVoxel = ~0u;
};
using RayBatch = std::vector<TravellingRay>;

// One frame of the object-space tracer: the voxel split, the owners' BVHs and the PEs' local
// work lists. Each PE touches only its own PeState and its own voxels' BVHs.
class ObjectSpaceFrame {
 public:
  ObjectSpaceFrame(const TraceJob& job, par::Runtime& rt, int voxelsPerPe)
      : job_(job),
        rt_(rt),
        split_(job.scene, {voxelCount(voxelsPerPe, rt.pes()), partitionMargin(job.scene, job.camera.position())}),
        owners_(assignVoxelOwners(split_, rt.pes())),
        integrator_(jobIntegrator(job)),
        films_(makeFilms(job, rt.pes(), integrator_->options().spp)),
        bvhs_(split_.voxels()),
        views_(job, rt.pes()),
        state_(rt.pes()) {}

  TraceResult run() {
    const int pes = rt_.pes();
    // Each owner builds the BVHs of its own voxels (task t: the voxels of PE t).
    rt_.runOnEachPe(job_.stage("build"), [&](par::Pe& pe) {
      std::vector<uint32_t> held;
      for (int v = 0; v < split_.voxels(); ++v)
        if (owners_[v] == pe.id() && !split_.triangles(v).empty()) {
          bvhs_[v] = Bvh(job_.scene.positions, job_.scene.triangles, split_.triangles(v), job_.options.bvh);
          held.insert(held.end(), split_.triangles(v).begin(), split_.triangles(v).end());
        }
      views_.build(pe.id(), held, integrator_->context().lights());
    });

    const std::vector<PixelRect> tiles = cameraTiles(job_.width, job_.height, job_.options.tileSizePx);
    const auto total = int64_t(tiles.size());
    std::atomic<int64_t> done{0};
    par::BatchedChannel<TravellingRay> rays(rt_, "rays", par::MessageKind::Rays, size_t(job_.options.rayBatch),
                                            [this](par::Pe& pe, RayBatch&& batch) {
                                              for (const TravellingRay& r : batch) trace(pe, r);
                                              par::flushIfDry(pe, *rays_);
                                            });
    rays_ = &rays;
    // Materials, textures, lights and the kd tree with the voxels' owners are replicated on
    // every PE, and so are the emitters (area-light sampling); other geometry is not.
    if (!job_.sceneResident) recordReplicatedData(rt_, job_.scene, integrator_->context().lights(), split_.treeBytes() + owners_.size() * sizeof(int));
    rt_.runStage(job_.stage("trace"), tileTaskSet(tiles, job_.options.tileSizePx), [&](par::Pe& pe, par::TaskId id) {
      PeState& st = state_[pe.id()];
      std::vector<RayMessage> camera;
      integrator_->cameraRays(tiles[size_t(id)], camera);
      countStartRays(st.stats, camera);
      for (const RayMessage& m : camera) trace(pe, TravellingRay{m, m.ray.tMin});
      par::flushIfDry(pe, *rays_);
      const int64_t n = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (job_.options.progress) job_.options.progress(n, total);
    });
    rays_ = nullptr;

    // Each PE's film contributions travel to the assembler, whose film is the image.
    {
      std::vector<Film*> films;
      for (const std::unique_ptr<Film>& f : films_) films.push_back(f.get());
      FilmAssembly assembly(rt_, *films_[kAssemblerPe]);
      if (job_.assembleImage) assembly.deliverFilms(rt_, films, tiles);
    }

    TraceResult result{films_[kAssemblerPe]->toImage(), {}, tiles.size()};
    PartitionHoldings held{std::vector<uint64_t>(size_t(pes), 0), std::vector<uint64_t>(size_t(pes), 0),
                           std::vector<uint64_t>(size_t(pes), 0)};
    for (int v = 0; v < split_.voxels(); ++v) {
      held.geometryBytes[owners_[v]] += bvhs_[v].stats().memoryBytes + split_.triangles(v).size() * kTriangleVertexBytes;
      held.triangles[owners_[v]] += split_.triangles(v).size();
      held.partitionsOwned[owners_[v]] += 1;
    }
    std::vector<TraceStats> raysTraced;
    for (int p = 0; p < pes; ++p) {
      const PeState& st = state_[size_t(p)];
      raysTraced.push_back(st.stats);
      rt_.addCounter("Partition/rays_sent", p, double(st.raysSent));
    }
    result.rays = recordRayCounters(rt_, raysTraced);
    recordPartitionHoldings(held, rt_);
    return result;
  }

 private:
  // Padded to a cache line: each PE writes only its own.
  struct alignas(64) PeState {
    std::vector<TravellingRay> work;  // rays to trace here, depth first
    std::vector<RayMessage> spawned;
    TraceStats stats;
    uint64_t raysSent = 0;
  };

  // On PE pe, inside a tile task or the "rays" handler: traces the ray through this PE's
  // voxels and everything it spawns here, sending rays that reach another owner's voxel.
  void trace(par::Pe& pe, const TravellingRay& first) {
    PeState& st = state_[pe.id()];
    st.work.push_back(first);
    while (!st.work.empty()) {
      const TravellingRay item = st.work.back();
      st.work.pop_back();
      advance(pe, st, item);
    }
  }

  // Walks the ray from where it entered this PE's voxel: traces it in each voxel this PE owns,
  // in order along the ray, until it hits, is blocked, or reaches another owner's voxel.
  void advance(par::Pe& pe, PeState& st, const TravellingRay& item) {
    const RayMessage& m = item.message;
    Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
    bool reached = item.voxel == TravellingRay::kStartVoxel;  // at the voxel the walk resumes in
    bool finished = false;  // hit, blocked or sent on
    auto visit = [&](const VoxelSpan& s) {
      if (!reached) {
        if (s.voxel != item.voxel) return true;
        reached = true;
      }
      finished = traceInVoxel(pe, st, m, s, emit);
      return !finished;
    };
    // The walk from tEnter gives the same spans from the voxel on as the walk from the origin,
    // unless the voxel's span has zero length at a corner the shorter walk steps past: then
    // the whole walk finds it.
    Ray resume = m.ray;
    resume.tMin = item.tEnter;
    split_.walk(resume, visit);
    if (!reached) split_.walk(m.ray, visit);
    PR_CHECK(reached, "object-space: a ray sent to a voxel its walk does not pass");
    if (!finished) integrator_->miss(m, emit);  // left the scene (a shadow ray: unoccluded)
  }

  // The ray in one voxel of its walk; true when the ray is done here (hit, blocked, or sent to
  // the voxel's owner).
  bool traceInVoxel(par::Pe& pe, PeState& st, const RayMessage& m, const VoxelSpan& s, Emit& emit) {
    const uint32_t v = s.voxel;
    if (split_.triangles(v).empty()) return false;  // nothing to hit: no owner needs the ray
    if (owners_[v] != pe.id()) {
      rays_->send(pe, owners_[v], TravellingRay{m, s.tEnter, v});
      ++st.raysSent;
      return true;
    }
    const Bvh& bvh = bvhs_[v];
    // Any occluder anywhere on the segment blocks a shadow ray, wherever it lies along the ray.
    if (m.kind == RayKind::Shadow) return bvh.occluded(m.ray);
    // Only hits up to the end of the span: a farther one may be behind a nearer triangle held
    // by a later voxel.
    Ray clipped = m.ray;
    clipped.tMax = std::min(m.ray.tMax, s.tExit);
    Hit hit;
    if (!bvh.intersect(clipped, hit)) return false;
    integrator_->shade(makeInteraction(views_.of(pe.id()), m.ray, hit), m, emit);
    for (const RayMessage& r : st.spawned) {
      ++(r.kind == RayKind::Shadow ? st.stats.shadowRays : st.stats.continuationRays);
      st.work.push_back(TravellingRay{r, r.ray.tMin});
    }
    st.spawned.clear();
    return true;
  }

  const TraceJob& job_;
  par::Runtime& rt_;
  VoxelSplit split_;
  std::vector<int> owners_;
  std::shared_ptr<const Integrator> integrator_;  // shade: one call per hit message handled
  std::vector<std::unique_ptr<Film>> films_;  // per PE: what it shaded; the assembler's is the image
  std::vector<Bvh> bvhs_;
  SceneViews views_;
  std::vector<PeState> state_;
  par::BatchedChannel<TravellingRay>* rays_ = nullptr;
};

}  // namespace

ObjectSpacePartition::ObjectSpacePartition(int voxelsPerPe) : voxelsPerPe_(voxelsPerPe) {
  if (voxelsPerPe < 1 || voxelsPerPe > kMaxVoxelsPerPe)
    throw InputError("object-space partitioning: " + std::to_string(voxelsPerPe) +
                     " voxels per PE requested, expected 1 to " + std::to_string(kMaxVoxelsPerPe));
}

TraceResult ObjectSpacePartition::render(const TraceJob& job, par::Runtime& rt) {
  checkRayBatch(job.options, "object-space partitioning");
  ObjectSpaceFrame frame(job, rt, voxelsPerPe_);
  return frame.run();
}

std::unique_ptr<Partition> makeObjectSpacePartition() { return std::make_unique<ObjectSpacePartition>(); }

}  // namespace pr::rt
