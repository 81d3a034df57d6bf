// The object-space tracer. Stage "split": the assembler's PE cuts the scene into voxels and deals
// them to the PEs. Stage "trace": each owner first builds one BVH over the triangles its voxels
// hold (the stage's set-up, so that an owner with less to build starts tracing while another
// still builds, as the dealing of voxels by build and trace work intends); then image tiles
// are tasks that make camera rays; a ray is traced on
// the PE owning the voxel it is in, and sent (a TravellingRay in a batch on the "rays"
// BatchedChannel) to the owner of the next voxel along it when it leaves without a hit; the
// owner resumes the walk at that voxel. Each run of consecutive voxels of one owner along the
// ray is one query of the owner's BVH, which accepts only a hit up to the end of the run, so
// the first run that reports a hit reports the ray's closest hit, the same one (bit for bit)
// as the BVH over the whole scene. A shadow ray is blocked by any occluder on it, found in
// any order: the PE that spawned it tests it whole (every BVH also holds the replicated
// emitters), then it visits each other owner with triangles of its own on the way once, in
// the order of their first such voxels, each testing the rest of the ray from there, and stops
// at the first that reports one; the owners visited travel with it. Shading and spawning happen
// on the PE that found the hit; new rays start from there. The stage ends when no tile, ray or message
// is left (termination.h). A ray passes another owner's voxel without visiting it when it
// misses the voxel's content boxes (voxel_split.h) there: through empty space. The voxels are
// cut at equal work where the camera rays land (view_work.h), and each tile names as its
// preferred PE the owner of the first voxel content its probe rays reach (tile_affinity.h).
#include "raytrace/partition/object_space.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <iterator>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "common/parallel/batched_channel.h"
#include "common/parallel/gather_to_root.h"
#include "raytrace/partition/film_assembly.h"
#include "common/util/error.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/tile_affinity.h"
#include "raytrace/partition/voxel_split.h"

namespace pr::rt {
namespace {

constexpr int kMaxVoxelsPerPe = 64;
constexpr int kMaxVoxels = 4096;  // VoxelSplit's limit

// k·P voxels, k lowered where k·P would pass the split's limit (P up to 4096 PEs).
int voxelCount(int voxelsPerPe, int pes) { return pes * std::max(1, std::min(voxelsPerPe, kMaxVoxels / pes)); }

// An owner's BVH build per triangle, in the time of one camera path sample's tracing: 0.27-0.28
// on both the hot-spot scene and the landscape in bench_partitioned at P = 1 (build per
// triangle over tracing per sample, path tracer; measured when the build was a stage of its
// own, before it became the trace stage's set-up).
constexpr float kBuildSamplesPerTriangle = 0.28f;

// The kd split of the job's scene into `voxels` voxels of about equal work where the camera
// rays land (view_work.h, in samples: pixels times spp), dealt to PEs by that work plus their
// BVH builds; a pre-pass program's rays do not start at the camera, so its split balances
// triangles.
VoxelSplit makeSplit(const TraceJob& job, int voxels, int spp, std::span<const uint32_t> emitters) {
  std::vector<WorkPoint> work;
  if (job.assembleImage && voxels > 1) {
    work = viewWork(job.scene, job.camera, job.width, job.height);
    for (WorkPoint& w : work) w.weight *= float(spp);
  }
  return VoxelSplit(job.scene, {voxels, partitionMargin(job.scene, job.camera.position()), work, emitters});
}

// A ray on its way to the owner of the next voxel along it: the message with its path state,
// and where the walk through the voxels resumes (the voxel and the ray parameter at which the
// ray enters it), so the owner continues the walk instead of restarting it from the origin.
struct TravellingRay {
  RayMessage message;
  float tEnter = 0.0f;
  uint32_t voxel = kStartVoxel;  // kStartVoxel: a new ray, traced from its first voxel
  // A shadow ray's owners that have tested the rest of it, bit p for PE p. Owners from 64 up
  // are not remembered: such an owner may get the ray again at a later voxel of its own and
  // test from there again, which is only redundant.
  uint64_t visited = 0;
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
        integrator_(jobIntegrator(job)),
        voxelsPerPe_(voxelsPerPe),
        films_(makeFilms(job, rt, integrator_->options().spp, kAssemblerPe)),
        bvhs_(rt.pes()),
        held_(rt.pes()),
        views_(job, rt),
        state_(rt.pes()) {}

  TraceResult run() {
    const int pes = rt_.pes();
    const std::vector<PixelRect> tiles = cameraTiles(job_.width, job_.height, job_.options.tileSizePx);
    // The split and the tiles' preferred PEs, on the assembler's PE alone: a serial part of the
    // method, timed as such. Across ranks the stage runs on each rank's first PE: rank 0's
    // makes them and sends them, the others decode them (every rank loaded the scene itself).
    std::vector<int> preferred;
    rt_.runOncePerRank(job_.stage("split"), [&](par::Pe& pe) {
      if (rt_.rank() == 0) {
        split_ = makeSplit(job_, voxelCount(voxelsPerPe_, pes), integrator_->options().spp, integrator_->context().lights().emitters());
        owners_ = assignVoxelOwners(split_, pes, kBuildSamplesPerTriangle);
        if (wantsTileAffinity(job_, pes)) preferred = firstOwners(tiles);
      }
      splitBytes_ = shareSplit(pe, preferred);
    });
    // Each owner's triangles leave PE 0 as messages; an owner builds from what it received.
    received_ = scene::sendPrimitiveShares(rt_, job_.scene, job_.stage("distribute"), [this](int p) { return trianglesOf(p); });

    const auto total = int64_t(tiles.size());
    const par::TaskSet tasks = tileTaskSet(tiles, job_.options.tileSizePx, preferred);
    std::atomic<int64_t> done{0};
    par::BatchedChannel<TravellingRay> rays(rt_, "rays", par::MessageKind::Rays, size_t(job_.options.rayBatch),
                                            [this](par::Pe& pe, RayBatch&& batch) {
                                              for (const TravellingRay& r : batch) trace(pe, r);
                                              par::flushIfDry(pe, *rays_);
                                            });
    rays_ = &rays;
    // Materials, textures, lights and the kd tree with the voxels' owners are replicated on
    // every PE, and so are the emitters (area-light sampling); other geometry is not.
    recordReplicatedData(rt_, job_, integrator_->context().lights(), 0, splitBytes_);
    rt_.runStage(job_.stage("trace"), tasks, [this](par::Pe& pe) { buildOwnBvh(pe); }, [&](par::Pe& pe, par::TaskId id) {
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
    for (int v = 0; v < split_.voxels(); ++v) held.partitionsOwned[owners_[v]] += 1;
    for (int p = 0; p < pes; ++p) {
      held.triangles[p] = held_[size_t(p)].size();
      held.geometryBytes[p] = bvhs_[size_t(p)].stats().memoryBytes + held_[size_t(p)].size() * kTriangleVertexBytes;
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

  // On each rank's first PE in the split stage, across ranks: rank 0's split, voxel owners and
  // the tiles' preferred PEs reach every rank.
  size_t shareSplit(par::Pe& pe, std::vector<int>& preferred) {
    return par::shareEncodedFromRank0(
        rt_, pe,
        [&](par::WireWriter& w) {
          split_.encode(w);
          w.sequence(std::span<const int>(owners_));
          w.sequence(std::span<const int>(preferred));
        },
        [&](par::WireReader& r) {
          split_ = VoxelSplit::decode(r);
          owners_ = r.sequence<int>();
          preferred = r.sequence<int>();
          if (owners_.size() != size_t(split_.voxels()))
            throw par::WireError("object-space: a voxel split whose owners do not match its voxels");
        });
  }

  // The triangles of PE p's voxels, sorted, a triangle straddling several of them once.
  std::vector<uint32_t> trianglesOf(int p) const {
    std::vector<uint32_t> held;
    for (int v = 0; v < split_.voxels(); ++v)
      if (owners_[v] == p) held.insert(held.end(), split_.triangles(v).begin(), split_.triangles(v).end());
    std::sort(held.begin(), held.end());
    held.erase(std::unique(held.begin(), held.end()), held.end());
    return held;
  }

  // On PE pe, before it traces anything: its view of the scene, from the share PE 0 sent it,
  // and one BVH over its voxels' triangles.
  void buildOwnBvh(par::Pe& pe) {
    std::vector<uint32_t>& held = held_[size_t(pe.id())];
    held = trianglesOf(pe.id());
    views_.build(pe.id(), held, integrator_->context().lights(), received_[size_t(pe.id())]);
    const scene::Scene& view = views_.of(pe.id());
    // The BVH also holds the PE's copy of the emitters (replicated for light sampling), so
    // that the PE spawning a shadow ray tests it against every emitter. A closest hit on one
    // outside this PE's voxels lies outside its runs, which are the only spans it traces.
    std::vector<uint32_t> emitters = integrator_->context().lights().emitters();
    std::sort(emitters.begin(), emitters.end());
    std::vector<uint32_t> traced;
    traced.reserve(held.size() + emitters.size());
    std::set_union(held.begin(), held.end(), emitters.begin(), emitters.end(), std::back_inserter(traced));
    if (!traced.empty()) bvhs_[size_t(pe.id())] = Bvh(view.positions, view.triangles, traced, job_.options.bvh);
  }

  // Per tile, the owner of the first voxel with content that most of its probe rays reach
  // (tile_affinity.h): a camera ray starting there is traced without being sent first. From
  // the replicated kd tree and content boxes alone.
  std::vector<int> firstOwners(const std::vector<PixelRect>& tiles) const {
    const std::vector<Ray> probes = affinityProbes(*integrator_, tiles);
    std::vector<int> owner(probes.size(), -1);
    for (size_t i = 0; i < probes.size(); ++i) {
      const RaySlabs slabs(probes[i]);
      split_.walk(probes[i], [&](const VoxelSpan& s) {
        if (!split_.reachesContent(s.voxel, slabs, s.tEnter, s.tExit)) return true;
        owner[i] = owners_[s.voxel];
        return false;
      });
    }
    return preferredPes(owner, tiles.size(), rt_.pes());
  }

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

  // Walks the ray from where it entered this PE's voxel: traces it through each run of this
  // PE's voxels along it, until it hits or reaches another owner's voxel.
  void advance(par::Pe& pe, PeState& st, const TravellingRay& item) {
    const RayMessage& m = item.message;
    if (m.kind == RayKind::Shadow) return advanceShadow(pe, st, item);
    Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
    bool finished = false;  // hit or sent on
    bool run = false;       // a run of this PE's voxels is open, over [runEnter, runExit]
    float runEnter = 0.0f, runExit = 0.0f;
    const RaySlabs slabs(m.ray);
    walkOn(item, [&](const VoxelSpan& s) {
      // A voxel of this PE's without triangles has nothing to hit; another owner's voxel the ray
      // crosses through empty space (always so for one without triangles) holds no hit in its
      // span: the walk goes on, and a run of this PE's voxels stays open across it.
      const bool mine = owners_[s.voxel] == pe.id();
      if (mine ? split_.triangles(s.voxel).empty() : !split_.reachesContent(s.voxel, slabs, s.tEnter, s.tExit)) return true;
      if (mine) {
        if (!run) runEnter = s.tEnter;
        run = true;
        runExit = s.tExit;
        return true;
      }
      finished = (run && traceRun(pe, st, m, runEnter, runExit, emit)) || sendOn(pe, st, m, s);
      run = false;
      return !finished;
    });
    if (!finished && run) finished = traceRun(pe, st, m, runEnter, runExit, emit);
    if (!finished) integrator_->miss(m, emit);  // left the scene
  }

  // A shadow ray, blocked by any occluder on it, found in any order. The PE that spawned it
  // tests the whole ray first: its BVH holds every emitter (replicated on every PE) besides its
  // voxels' triangles. Then each other owner on its way, in the order of its first voxel with
  // triangles only it holds along the ray, tests the rest of the ray from there (a hit before
  // lies in an earlier owner's voxel, tested there) and, when that finds none, walks on to the
  // next owner not yet visited. So a ray towards an area light is not sent to the light's owner
  // for the end of its way, where only the light is.
  void advanceShadow(par::Pe& pe, PeState& st, const TravellingRay& item) {
    const RayMessage& m = item.message;
    const Bvh& bvh = bvhs_[size_t(pe.id())];
    const int pes = rt_.pes();
    uint64_t visited = item.visited;
    bool tested = false;    // by this PE, in this call
    bool finished = false;  // blocked or sent on
    // Once every PE has tested, the rest of the walk can find no owner to visit.
    auto allVisited = [&] { return pes <= 64 && std::popcount(visited) == pes; };
    auto test = [&](float tEnter) {
      Ray rest = m.ray;
      rest.tMin = std::max(m.ray.tMin, tEnter);
      finished = bvh.occluded(rest);
      tested = true;
      if (pe.id() < 64) visited |= uint64_t{1} << pe.id();
    };
    if (item.voxel == TravellingRay::kStartVoxel) test(m.ray.tMin);
    if (!finished && !allVisited()) {
      const RaySlabs slabs(m.ray);
      walkOn(item, [&](const VoxelSpan& s) {
        const int owner = owners_[s.voxel];
        const bool done = owner == pe.id() ? tested : owner < 64 && (visited >> owner & 1u) != 0;
        // Content tests are the costly part of the walk: none for an owner that has tested.
        if (done || !split_.reachesHeldOnly(s.voxel, slabs, s.tEnter, s.tExit)) return true;
        if (owner != pe.id()) {
          finished = sendOn(pe, st, m, s, visited);
          return false;
        }
        test(s.tEnter);
        return !finished && !allVisited();
      });
    }
    if (finished) return;
    Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
    integrator_->miss(m, emit);  // no owner holds an occluder: unoccluded
  }

  // Walks the ray's voxels from the one where it entered this PE's (all of them for a new ray),
  // calling visit(const VoxelSpan&) until it returns false. The walk from tEnter gives the
  // same spans from that voxel on as the walk from the origin, unless the voxel's span has zero
  // length at a corner the shorter walk steps past: then the whole walk finds it.
  template <class Visit>
  void walkOn(const TravellingRay& item, Visit&& visit) const {
    bool reached = item.voxel == TravellingRay::kStartVoxel;
    auto fromVoxel = [&](const VoxelSpan& s) {
      if (!reached) {
        if (s.voxel != item.voxel) return true;
        reached = true;
      }
      return visit(s);
    };
    Ray resume = item.message.ray;
    resume.tMin = std::max(resume.tMin, item.tEnter);
    split_.walk(resume, fromVoxel);
    if (!reached) split_.walk(item.message.ray, fromVoxel);
    PR_CHECK(reached, "object-space: a ray sent to a voxel its walk does not pass");
  }

  // The ray in a run of this PE's voxels over [runEnter, runExit]: true when it hits there.
  bool traceRun(par::Pe& pe, PeState& st, const RayMessage& m, float runEnter, float runExit, Emit& emit) {
    // Only hits up to the end of the run: a farther one may be behind a nearer triangle held
    // by a later voxel. And none before its start: a hit there lies in an earlier voxel, whose
    // owner holds the triangle and found no hit up to this run (spans share their boundary
    // value, and tMin and tMax are both inclusive), so the BVH skips the nodes behind the run.
    Ray clipped = m.ray;
    clipped.tMin = std::max(m.ray.tMin, runEnter);
    clipped.tMax = std::min(m.ray.tMax, runExit);
    Hit hit;
    if (!bvhs_[size_t(pe.id())].intersect(clipped, hit)) return false;
    integrator_->shade(makeInteraction(views_.of(pe.id()), m.ray, hit), m, emit);
    for (const RayMessage& r : st.spawned) {
      ++(r.kind == RayKind::Shadow ? st.stats.shadowRays : st.stats.continuationRays);
      st.work.push_back(TravellingRay{r, r.ray.tMin});
    }
    st.spawned.clear();
    return true;
  }

  // Sends the ray to the owner of the voxel of span s, where its walk resumes. Always true.
  bool sendOn(par::Pe& pe, PeState& st, const RayMessage& m, const VoxelSpan& s, uint64_t visited = 0) {
    rays_->send(pe, owners_[s.voxel], TravellingRay{m, s.tEnter, s.voxel, visited});
    ++st.raysSent;
    return true;
  }

  const TraceJob& job_;
  par::Runtime& rt_;
  std::shared_ptr<const Integrator> integrator_;  // shade: one call per hit message handled
  int voxelsPerPe_;
  VoxelSplit split_;  // and owners_: made in the "split" stage
  std::vector<int> owners_;
  size_t splitBytes_ = 0;  // their encoding, with the tiles' preferred PEs: what PE 0 shares
  std::vector<std::unique_ptr<Film>> films_;  // per PE: what it shaded; the assembler's is the image
  std::vector<Bvh> bvhs_;                    // per PE, over its voxels' triangles and the emitters
  std::vector<std::vector<uint32_t>> held_;  // per PE: those triangles, ascending
  SceneViews views_;
  std::vector<scene::PrimitiveBatch> received_;  // per PE of this rank: the share PE 0 sent it
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
