// The object-space tracer. Stage "build": each owner's voxels get a BVH over the triangles
// they hold. Stage "trace": image tiles are tasks that make camera rays; a ray is traced on
// the PE owning the voxel it is in, and sent (a TravellingRay message on the "rays" Channel)
// to the owner of the next voxel along it when it leaves without a hit. A voxel accepts only a
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

#include "common/parallel/channel.h"
#include "raytrace/partition/film_assembly.h"
#include "common/util/error.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/voxel_split.h"

namespace pr::rt {
namespace {

constexpr int kMaxVoxelsPerPe = 64;

// A ray on its way: the message with its path state, and the index (in the ray's walk
// through the voxels, which every PE recomputes identically) of the voxel to trace next.
struct TravellingRay {
  RayMessage message;
  uint32_t span = 0;
};

// One frame of the object-space tracer: the voxel split, the owners' BVHs and the PEs' local
// work lists. Each PE touches only its own PeState and its own voxels' BVHs.
class ObjectSpaceFrame {
 public:
  ObjectSpaceFrame(const TraceJob& job, par::Runtime& rt, int voxelsPerPe)
      : job_(job),
        rt_(rt),
        split_(job.scene, {voxelsPerPe * rt.pes(), partitionMargin(job.scene, job.camera.position())}),
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
    par::Channel<TravellingRay> rays(rt_, "rays", par::MessageKind::Rays, [this](par::Pe& pe, TravellingRay&& r) { trace(pe, r); });
    rays_ = &rays;
    // Materials, textures, lights and the kd tree with the voxels' owners are replicated on
    // every PE, and so are the emitters (area-light sampling); other geometry is not.
    if (!job_.sceneResident) recordReplicatedData(rt_, job_.scene, integrator_->context().lights(), split_.treeBytes() + owners_.size() * sizeof(int));
    rt_.runStage(job_.stage("trace"), tileTaskSet(tiles, job_.options.tileSizePx), [&](par::Pe& pe, par::TaskId id) {
      PeState& st = state_[pe.id()];
      std::vector<RayMessage> camera;
      integrator_->cameraRays(tiles[size_t(id)], camera);
      countStartRays(st.stats, camera);
      for (const RayMessage& m : camera) trace(pe, TravellingRay{m, 0});
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
      rt_.addCounter("Partition/ray_messages_sent", p, double(st.raysSent));
    }
    result.rays = recordRayCounters(rt_, raysTraced);
    recordPartitionHoldings(held, rt_);
    return result;
  }

 private:
  // Padded to a cache line: each PE writes only its own.
  struct alignas(64) PeState {
    std::vector<TravellingRay> work;  // rays to trace here, depth first
    std::vector<VoxelSpan> spans;
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

  void advance(par::Pe& pe, PeState& st, const TravellingRay& item) {
    const RayMessage& m = item.message;
    st.spans.clear();
    split_.walk(m.ray, [&](const VoxelSpan& s) {
      st.spans.push_back(s);
      return true;
    });
    Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
    for (size_t k = item.span; k < st.spans.size(); ++k) {
      const uint32_t v = st.spans[k].voxel;
      if (split_.triangles(v).empty()) continue;  // nothing to hit: no owner needs the ray
      if (owners_[v] != pe.id()) {
        rays_->send(pe, owners_[v], TravellingRay{m, uint32_t(k)});
        ++st.raysSent;
        return;
      }
      const Bvh& bvh = bvhs_[v];
      if (m.kind == RayKind::Shadow) {
        // Any occluder anywhere on the segment blocks it, wherever it lies along the ray.
        if (bvh.occluded(m.ray)) return;
        continue;
      }
      // Only hits up to the end of the span: a farther one may be behind a nearer triangle
      // held by a later voxel.
      Ray clipped = m.ray;
      clipped.tMax = std::min(m.ray.tMax, st.spans[k].tExit);
      Hit hit;
      if (!bvh.intersect(clipped, hit)) continue;
      integrator_->shade(makeInteraction(views_.of(pe.id()), m.ray, hit), m, emit);
      for (const RayMessage& r : st.spawned) {
        ++(r.kind == RayKind::Shadow ? st.stats.shadowRays : st.stats.continuationRays);
        st.work.push_back(TravellingRay{r, 0});
      }
      st.spawned.clear();
      return;
    }
    integrator_->miss(m, emit);  // left the scene (a shadow ray: unoccluded)
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
  par::Channel<TravellingRay>* rays_ = nullptr;
};

}  // namespace

ObjectSpacePartition::ObjectSpacePartition(int voxelsPerPe) : voxelsPerPe_(voxelsPerPe) {
  if (voxelsPerPe < 1 || voxelsPerPe > kMaxVoxelsPerPe)
    throw InputError("object-space partitioning: " + std::to_string(voxelsPerPe) +
                     " voxels per PE requested, expected 1 to " + std::to_string(kMaxVoxelsPerPe));
}

TraceResult ObjectSpacePartition::render(const TraceJob& job, par::Runtime& rt) {
  ObjectSpaceFrame frame(job, rt, voxelsPerPe_);
  return frame.run();
}

std::unique_ptr<Partition> makeObjectSpacePartition() { return std::make_unique<ObjectSpacePartition>(); }

}  // namespace pr::rt
