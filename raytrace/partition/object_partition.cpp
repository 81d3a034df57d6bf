// The object-partitioning tracer. Stage "build": each owner builds one BVH over its pieces'
// triangles. Stage "trace": image tiles are tasks that make camera rays on their PE, which
// becomes the rays' originator. The originator keeps a pending record per ray, sends a
// RayQuery to each owner whose piece bounds the ray can reach ("queries" Channel; its own
// pieces it answers itself), and merges the HitReply messages ("hits" Channel) in the
// deterministic order of Hit::closerThan, so the result does not depend on arrival order. A
// hit reply carries the SurfaceInteraction the owner made from its own geometry; the
// originator shades with it and originates the spawned rays. Shadow queries return one bit.
#include "raytrace/partition/object_partition.h"

#include <atomic>
#include <memory>
#include <vector>

#include "common/parallel/channel.h"
#include "raytrace/partition/film_assembly.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/partition_margin.h"

namespace pr::rt {
namespace {

// To an owner: the ray (not its path state, which stays with the originator) and where the
// answer goes.
struct RayQuery {
  Ray ray;
  uint32_t slot = 0;    // the originator's pending record
  uint16_t origin = 0;  // the originator PE
  bool shadow = false;
};

// Back to the originator. A miss or a shadow answer is only the header (slot and flag); a hit
// carries the hit record and the interaction made by the owner of the hit triangle.
struct HitReply {
  uint32_t slot = 0;
  bool found = false;  // a hit (closest-hit query) or an occluder (shadow query)
  Hit hit;
  SurfaceInteraction si;
};
constexpr size_t kReplyHeaderBytes = 8;

class ObjectFrame {
 public:
  ObjectFrame(const TraceJob& job, par::Runtime& rt, uint32_t maxPieceTriangles)
      : job_(job),
        rt_(rt),
        assignment_(job.scene, {rt.pes(), maxPieceTriangles, partitionMargin(job.scene, job.camera.position())}),
        integrator_(jobIntegrator(job)),
        films_(makeFilms(job, rt.pes(), integrator_->options().spp)),
        bvhs_(rt.pes()),
        views_(job, rt.pes()),
        state_(rt.pes()) {}

  TraceResult run() {
    const int pes = rt_.pes();
    rt_.runOnEachPe(job_.stage("build"), [&](par::Pe& pe) {
      const int p = pe.id();
      if (!assignment_.triangles(p).empty())
        bvhs_[size_t(p)] = Bvh(job_.scene.positions, job_.scene.triangles, assignment_.triangles(p), job_.options.bvh);
      views_.build(p, assignment_.triangles(p), integrator_->context().lights());
    });

    const std::vector<PixelRect> tiles = cameraTiles(job_.width, job_.height, job_.options.tileSizePx);
    const auto total = int64_t(tiles.size());
    std::atomic<int64_t> done{0};
    par::Channel<RayQuery> queries(rt_, "queries", par::MessageKind::Rays, [this](par::Pe& pe, RayQuery&& q) { answerRemote(pe, q); });
    par::Channel<HitReply> hits(rt_, "hits", par::MessageKind::Rays, [this](par::Pe& pe, HitReply&& r) {
      merge(pe, r);
      drain(pe);
    });
    queries_ = &queries;
    hits_ = &hits;
    // Materials, textures, lights and the directory of piece bounds and owners are replicated
    // on every PE, and so are the emitters (area-light sampling); other geometry is not.
    if (!job_.sceneResident) recordReplicatedData(rt_, job_.scene, integrator_->context().lights(), assignment_.directoryBytes());
    rt_.runStage(job_.stage("trace"), tileTaskSet(tiles, job_.options.tileSizePx), [&](par::Pe& pe, par::TaskId id) {
      PeState& st = state_[pe.id()];
      const size_t before = st.start.size();
      integrator_->cameraRays(tiles[size_t(id)], st.start);
      countStartRays(st.stats, std::span<const RayMessage>(st.start).subspan(before));
      drain(pe);
      const int64_t n = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (job_.options.progress) job_.options.progress(n, total);
    });
    queries_ = nullptr;
    hits_ = nullptr;

    // Each PE's film contributions travel to the assembler, whose film is the image.
    {
      std::vector<Film*> films;
      for (const std::unique_ptr<Film>& f : films_) films.push_back(f.get());
      FilmAssembly assembly(rt_, *films_[kAssemblerPe]);
      if (job_.assembleImage) assembly.deliverFilms(rt_, films, tiles);
    }

    TraceResult result{films_[kAssemblerPe]->toImage(), {}, tiles.size()};
    PartitionHoldings held;
    for (int p = 0; p < pes; ++p) {
      const uint64_t n = assignment_.triangles(p).size();
      held.triangles.push_back(n);
      held.geometryBytes.push_back(bvhs_[p].stats().memoryBytes + n * kTriangleVertexBytes);
      held.partitionsOwned.push_back(assignment_.piecesOf(p).size());
    }
    std::vector<TraceStats> raysTraced;
    for (int p = 0; p < pes; ++p) {
      const PeState& st = state_[size_t(p)];
      PR_CHECK(st.live == 0, "object partitioning: a ray still waits for hit replies after the stage");
      raysTraced.push_back(st.stats);
      rt_.addCounter("Partition/ray_queries_sent", p, double(st.queriesSent));
      rt_.addCounter("Partition/hit_replies_sent", p, double(st.repliesSent));
    }
    result.rays = recordRayCounters(rt_, raysTraced);
    recordPartitionHoldings(held, rt_);
    return result;
  }

 private:
  struct Pending {
    RayMessage message;
    uint32_t remaining = 0;  // replies still to come
    HitReply best;           // closest hit so far (found = false: none yet)
  };
  // Padded to a cache line: each PE writes only its own.
  struct alignas(64) PeState {
    std::vector<RayMessage> start;  // rays this PE originates, not yet sent
    std::vector<Pending> pending;
    std::vector<uint32_t> freeSlots;
    std::vector<int> owners;
    std::vector<RayMessage> spawned;
    TraceStats stats;
    uint64_t queriesSent = 0, repliesSent = 0;
    size_t live = 0;  // pending records in use
  };

  // On the originator: sends every ray waiting in its start list to the owners it can reach.
  void drain(par::Pe& pe) {
    PeState& st = state_[pe.id()];
    while (!st.start.empty()) {
      const RayMessage m = st.start.back();
      st.start.pop_back();
      launch(pe, st, m);
    }
  }

  void launch(par::Pe& pe, PeState& st, const RayMessage& m) {
    assignment_.ownersAlong(m.ray, st.owners);
    if (st.owners.empty()) {
      Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
      integrator_->miss(m, emit);  // reaches no object: nothing to ask
      return;
    }
    uint32_t slot;
    if (!st.freeSlots.empty()) {
      slot = st.freeSlots.back();
      st.freeSlots.pop_back();
    } else {
      slot = uint32_t(st.pending.size());
      st.pending.emplace_back();
    }
    ++st.live;
    st.pending[slot] = Pending{m, uint32_t(st.owners.size()), HitReply{}};
    const bool shadow = m.kind == RayKind::Shadow;
    bool local = false;
    for (int owner : st.owners) {
      if (owner == pe.id()) {
        local = true;
        continue;
      }
      queries_->send(pe, owner, RayQuery{m.ray, slot, uint16_t(pe.id()), shadow});
      ++st.queriesSent;
    }
    // The own pieces last: their answer may complete the record, which must not be reused
    // while queries naming it are still being sent.
    if (local) merge(pe, answer(pe.id(), m.ray, slot, shadow));
  }

  // On an owner: the nearest hit among its own triangles (or whether any occludes).
  HitReply answer(int pe, const Ray& ray, uint32_t slot, bool shadow) const {
    HitReply r;
    r.slot = slot;
    const Bvh& bvh = bvhs_[pe];
    if (shadow) {
      r.found = bvh.occluded(ray);
    } else if (bvh.intersect(ray, r.hit)) {
      r.found = true;
      r.si = makeInteraction(views_.of(pe), ray, r.hit);
    }
    return r;
  }

  void answerRemote(par::Pe& pe, const RayQuery& q) {
    PeState& st = state_[pe.id()];
    HitReply r = answer(pe.id(), q.ray, q.slot, q.shadow);
    const size_t bytes = r.found && !q.shadow ? sizeof(HitReply) : kReplyHeaderBytes;
    hits_->send(pe, q.origin, std::move(r), bytes);
    ++st.repliesSent;
  }

  // On the originator: folds one reply into the pending record; the last one resolves it.
  void merge(par::Pe& pe, const HitReply& r) {
    PeState& st = state_[pe.id()];
    Pending& p = st.pending[r.slot];
    PR_CHECK(p.remaining > 0, "object partitioning: reply for a ray that expects none");
    if (r.found && (!p.best.found || r.hit.closerThan(p.best.hit))) p.best = r;
    if (--p.remaining > 0) return;
    const Pending done = p;
    st.freeSlots.push_back(r.slot);
    --st.live;
    Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
    if (done.message.kind == RayKind::Shadow) {
      if (!done.best.found) integrator_->miss(done.message, emit);
      return;
    }
    if (!done.best.found) {
      integrator_->miss(done.message, emit);
      return;
    }
    integrator_->shade(done.best.si, done.message, emit);
    for (const RayMessage& s : st.spawned) {
      ++(s.kind == RayKind::Shadow ? st.stats.shadowRays : st.stats.continuationRays);
      st.start.push_back(s);
    }
    st.spawned.clear();
  }

  const TraceJob& job_;
  par::Runtime& rt_;
  ObjectAssignment assignment_;
  std::shared_ptr<const Integrator> integrator_;  // shade: one call per hit message handled
  std::vector<std::unique_ptr<Film>> films_;  // per PE: what it shaded; the assembler's is the image
  std::vector<Bvh> bvhs_;
  SceneViews views_;
  std::vector<PeState> state_;
  par::Channel<RayQuery>* queries_ = nullptr;
  par::Channel<HitReply>* hits_ = nullptr;
};

}  // namespace

TraceResult ObjectPartition::render(const TraceJob& job, par::Runtime& rt) {
  ObjectFrame frame(job, rt, maxPieceTriangles_);
  return frame.run();
}

std::unique_ptr<Partition> makeObjectPartition() { return std::make_unique<ObjectPartition>(); }

}  // namespace pr::rt
