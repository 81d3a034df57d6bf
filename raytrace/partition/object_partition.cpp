// The object-partitioning tracer. Stage "split": the assembler's PE cuts the scene into object
// pieces, deals them to the PEs and makes the owner directory. Stage "build": each owner builds
// one BVH over its pieces' triangles. Stage "trace": image tiles are tasks that make camera rays on their PE, which
// becomes the rays' originator. The originator looks up, in the replicated owner directory
// (owner_directory.h), the owners the ray can reach and where, and asks them one at a time,
// nearest first: each RayQuery carries the closest hit so far as its tMax, and the ray is
// resolved once no owner is left whose entry is no farther than that hit (its own pieces it
// answers itself, without a message). Queries and HitReply answers travel in batches per
// destination ("queries" and "hits" BatchedChannels). Replies are folded in the deterministic
// order of Hit::closerThan, so the image does not depend on arrival order. A hit reply carries
// the SurfaceInteraction the owner made from its own geometry; the originator shades with it
// and originates the spawned rays. A shadow ray stops at the first owner with an occluder.
// Replicated pieces (object_assignment.h) are in every PE's second BVH: the directory lists
// them as the owner kEveryPe, which the originator answers itself, like its own pieces.
// Each tile names as its preferred PE the owner most of its probe rays hit first
// (tile_affinity.h; stage "affinity" gathers the owners' probe hits on PE 0): under the
// preferred-bias schedule a tile starts where its rays are answered without a message.
#include "raytrace/partition/object_partition.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <vector>

#include "common/parallel/batched_channel.h"
#include "common/parallel/gather_to_root.h"
#include "raytrace/partition/film_assembly.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/owner_directory.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/tile_affinity.h"

namespace pr::rt {
namespace {

// To an owner: the ray (not its path state, which stays with the originator; tMax is the
// closest hit so far) and where the answer goes.
struct RayQuery {
  Ray ray;
  uint32_t slot = 0;    // the originator's pending record
  uint16_t origin = 0;  // the originator PE
  bool shadow = false;
};

// Back to the originator. A miss or a shadow answer is only the header (slot and flags); a hit
// carries the hit record and the interaction made by the owner of the hit triangle.
struct HitReply {
  uint32_t slot = 0;
  bool found = false;       // a hit (closest-hit query) or an occluder (shadow query)
  bool carriesHit = false;  // a closest hit: hit and si follow the header
  Hit hit;
  SurfaceInteraction si;
};
using QueryBatch = std::vector<RayQuery>;
using ReplyBatch = std::vector<HitReply>;

}  // namespace
}  // namespace pr::rt

// A reply on the wire: slot (4 bytes), the two flags (1 each, 2 padding), then the hit and its
// interaction when it carries them.
namespace pr::par {
template <>
struct Wire<rt::HitReply> {
  static_assert(std::is_trivially_copyable_v<rt::Hit> && std::is_trivially_copyable_v<rt::SurfaceInteraction>);
  static constexpr bool kBytewise = false;
  static constexpr std::size_t kHeaderBytes = 8;
  static std::size_t size(const rt::HitReply& r) {
    return kHeaderBytes + (r.carriesHit ? sizeof(rt::Hit) + sizeof(rt::SurfaceInteraction) : 0);
  }
  static void encode(const rt::HitReply& r, WireWriter& w) {
    const std::uint8_t header[kHeaderBytes] = {std::uint8_t(r.slot), std::uint8_t(r.slot >> 8), std::uint8_t(r.slot >> 16),
                                               std::uint8_t(r.slot >> 24), r.found, r.carriesHit, 0, 0};
    w.raw(header, sizeof header);
    if (r.carriesHit) {
      w.value(r.hit);
      w.value(r.si);
    }
  }
  static rt::HitReply decode(WireReader& r) {
    std::uint8_t header[kHeaderBytes];
    r.raw(header, sizeof header);
    rt::HitReply out;
    out.slot = std::uint32_t(header[0]) | std::uint32_t(header[1]) << 8 | std::uint32_t(header[2]) << 16 | std::uint32_t(header[3]) << 24;
    out.found = header[4] != 0;
    out.carriesHit = header[5] != 0;
    if (out.carriesHit) {
      out.hit = r.value<rt::Hit>();
      out.si = r.value<rt::SurfaceInteraction>();
    }
    return out;
  }
};
}  // namespace pr::par

namespace pr::rt {
namespace {

class ObjectFrame {
 public:
  ObjectFrame(const TraceJob& job, par::Runtime& rt, uint32_t maxPieceTriangles, double replicatedFraction)
      : job_(job),
        rt_(rt),
        maxPieceTriangles_(maxPieceTriangles),
        replicatedFraction_(replicatedFraction),
        integrator_(jobIntegrator(job)),
        films_(makeFilms(job, rt, integrator_->options().spp, kAssemblerPe)),
        bvhs_(rt.pes()),
        replicas_(rt.pes()),
        views_(job, rt),
        state_(rt.pes()) {}

  TraceResult run() {
    const int pes = rt_.pes();
    const std::vector<PixelRect> tiles = cameraTiles(job_.width, job_.height, job_.options.tileSizePx);
    // The pieces, their owners, the owner directory and the tiles' probe rays, on the
    // assembler's PE alone: a serial part of the method, timed as such. Across ranks the stage
    // runs on each rank's first PE: rank 0's makes the assignment and sends it, and every rank
    // makes the directory and the probes from it (every rank loaded the scene itself).
    std::vector<Ray> probes;
    rt_.runOncePerRank(job_.stage("split"), [&](par::Pe& pe) {
      if (rt_.rank() == 0)
        assignment_ = ObjectAssignment(
            job_.scene, {pes, maxPieceTriangles_, partitionMargin(job_.scene, job_.camera.position()), replicatedFraction_});
      assignmentBytes_ = shareAssignment(pe);
      directory_ = OwnerDirectory(assignment_);
      if (wantsTileAffinity(job_, pes)) probes = affinityProbes(*integrator_, tiles);
    });
    std::vector<std::vector<float>> nearest(static_cast<size_t>(pes));  // per PE: its probe hits
    std::vector<float> shared;  // the replicated pieces' probe hits, on the controller's PE
    // Each owner's pieces, and the replicated ones, leave PE 0 as messages; an owner builds
    // from what it received.
    const auto heldBy = [&](int p) {
      std::vector<uint32_t> held(assignment_.triangles(p).begin(), assignment_.triangles(p).end());
      held.insert(held.end(), assignment_.replicated().begin(), assignment_.replicated().end());
      std::sort(held.begin(), held.end());
      return held;
    };
    const std::vector<scene::PrimitiveBatch> received = scene::sendPrimitiveShares(rt_, job_.scene, job_.stage("distribute"), heldBy);
    rt_.runOnEachPe(job_.stage("build"), [&](par::Pe& pe) {
      const int p = pe.id();
      views_.build(p, heldBy(p), integrator_->context().lights(), received[size_t(p)]);
      const scene::Scene& view = views_.of(p);
      if (!assignment_.triangles(p).empty())
        bvhs_[size_t(p)] = Bvh(view.positions, view.triangles, assignment_.triangles(p), job_.options.bvh);
      if (!assignment_.replicated().empty())
        replicas_[size_t(p)] = Bvh(view.positions, view.triangles, assignment_.replicated(), job_.options.bvh);
      if (probes.empty()) return;
      nearest[size_t(p)] = nearestHits(bvhs_[size_t(p)], probes);
      if (p == kAssemblerPe && !assignment_.replicated().empty()) shared = nearestHits(replicas_[size_t(p)], probes);
    });
    // The probe hits travel to the controller's PE, where the tiles' preferred PEs are chosen.
    if (!probes.empty())
      nearest = par::gatherToRoot(rt_, job_.stage("affinity"), "affinity", par::MessageKind::Results, std::move(nearest),
                                  sizeof(float), kAssemblerPe);
    std::vector<int> preferred;
    if (!probes.empty()) {
      // Chosen where the probe hits are, on rank 0; the other ranks receive its choice.
      preferred = rt_.rank() == 0 ? preferredPes(nearestOwners(nearest, shared), tiles.size(), pes) : std::vector<int>(tiles.size());
      preferredFromRank0(preferred);
    }
    const par::TaskSet tasks = tileTaskSet(tiles, job_.options.tileSizePx, preferred);

    const auto total = int64_t(tiles.size());
    std::atomic<int64_t> done{0};
    const auto batch = size_t(job_.options.rayBatch);
    par::BatchedChannel<RayQuery> queries(rt_, "queries", par::MessageKind::Rays, batch, [this](par::Pe& pe, QueryBatch&& b) {
      for (const RayQuery& q : b) answerRemote(pe, q);
      par::flushIfDry(pe, *queries_, *hits_);
    });
    par::BatchedChannel<HitReply> hits(rt_, "hits", par::MessageKind::Rays, batch, [this](par::Pe& pe, ReplyBatch&& b) {
      for (const HitReply& r : b) {
        fold(pe, r);
        drain(pe);
      }
      par::flushIfDry(pe, *queries_, *hits_);
    });
    queries_ = &queries;
    hits_ = &hits;
    // Materials, textures, lights and the owner directory are replicated on every PE, and so
    // are the emitters (area-light sampling); the geometry, the replicated pieces included,
    // reached the PEs as messages (the distribute stage).
    recordReplicatedData(rt_, job_, integrator_->context().lights(), 0, assignmentBytes_);
    rt_.runStage(job_.stage("trace"), tasks, [&](par::Pe& pe, par::TaskId id) {
      PeState& st = state_[pe.id()];
      const size_t before = st.start.size();
      integrator_->cameraRays(tiles[size_t(id)], st.start);
      countStartRays(st.stats, std::span<const RayMessage>(st.start).subspan(before));
      drain(pe);
      par::flushIfDry(pe, *queries_, *hits_);
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
      const uint64_t n = assignment_.triangles(p).size() + assignment_.replicated().size();
      held.triangles.push_back(n);
      held.geometryBytes.push_back(bvhs_[p].stats().memoryBytes + replicas_[p].stats().memoryBytes + n * kTriangleVertexBytes);
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
    std::vector<OwnerEntry> owners;  // to ask, nearest first
    uint32_t next = 0;               // owners[next] is the next to ask
    bool waiting = false;            // a query is out
    HitReply best;                   // closest hit so far (found = false: none yet)
  };
  // Padded to a cache line: each PE writes only its own.
  struct alignas(64) PeState {
    std::vector<RayMessage> start;  // rays this PE originates, not yet sent
    std::vector<Pending> pending;   // records are reused, keeping their owner lists' storage
    std::vector<uint32_t> freeSlots;
    std::vector<RayMessage> spawned;
    std::vector<OwnerDirectory::NodeEntry> heap;  // the owner directory's walk
    TraceStats stats;
    uint64_t queriesSent = 0, repliesSent = 0;
    size_t live = 0;  // pending records in use
  };

  // On each rank's first PE in the split stage, across ranks: rank 0's assignment reaches
  // every rank.
  size_t shareAssignment(par::Pe& pe) {
    return par::shareEncodedFromRank0(
        rt_, pe, [&](par::WireWriter& w) { assignment_.encode(w); },
        [&](par::WireReader& r) {
          assignment_ = ObjectAssignment::decode(r);
          if (assignment_.pes() != rt_.pes()) throw par::WireError("object partitioning: an assignment for another number of PEs");
        });
  }

  // Between stages, across ranks: the tiles' preferred PEs, chosen on rank 0 where the probe
  // hits were gathered, reach every rank (a sum in which only rank 0's values are not zero),
  // so every rank's task set names the same PEs.
  void preferredFromRank0(std::vector<int>& preferred) {
    if (rt_.ranks() == 1) return;
    std::vector<double> values(preferred.size());
    if (rt_.rank() == 0) std::copy(preferred.begin(), preferred.end(), values.begin());
    rt_.sumAcrossRanks(values);
    std::transform(values.begin(), values.end(), preferred.begin(), [](double v) { return int(v); });
  }

  // The nearest hit of each probe on bvh's triangles (kInfinity: none).
  static std::vector<float> nearestHits(const Bvh& bvh, const std::vector<Ray>& probes) {
    std::vector<float> t;
    t.reserve(probes.size());
    for (const Ray& r : probes) {
      Hit hit;
      t.push_back(bvh.intersect(r, hit) ? hit.t : kInfinity);
    }
    return t;
  }

  // On the originator: starts every ray waiting in its start list.
  void drain(par::Pe& pe) {
    PeState& st = state_[pe.id()];
    while (!st.start.empty()) {
      const RayMessage m = st.start.back();
      st.start.pop_back();
      launch(pe, st, m);
    }
  }

  void launch(par::Pe& pe, PeState& st, const RayMessage& m) {
    uint32_t slot;
    if (!st.freeSlots.empty()) {
      slot = st.freeSlots.back();
      st.freeSlots.pop_back();
    } else {
      slot = uint32_t(st.pending.size());
      st.pending.emplace_back();
    }
    ++st.live;
    Pending& p = st.pending[slot];
    p.message = m;
    p.waiting = false;
    p.best = HitReply{};
    p.best.slot = slot;
    directory_.ownersNearestFirst(m.ray, -1, p.owners, st.heap);
    p.next = 0;
    ask(pe, st, slot);
  }

  // On the originator: asks the owners the ray reaches nearest first, its own pieces at once
  // and another owner by a query, each bounded by the closest hit so far, until one is found
  // nearer than the next owner's entry (or an occluder); then resolves the ray.
  void ask(par::Pe& pe, PeState& st, uint32_t slot) {
    Pending& p = st.pending[slot];
    const bool shadow = p.message.kind == RayKind::Shadow;
    while (p.next < p.owners.size() && !(shadow && p.best.found)) {
      const OwnerEntry e = p.owners[p.next];
      if (p.best.found && e.t > p.best.hit.t) break;  // every owner left starts farther
      ++p.next;
      Ray ray = p.message.ray;
      if (p.best.found) ray.tMax = p.best.hit.t;  // inclusive: an equal t with a lower triangle still wins
      if (e.owner == pe.id() || e.owner == kEveryPe) {
        merge(p, answer(pe.id(), e.owner == kEveryPe ? replicas_[pe.id()] : bvhs_[pe.id()], ray, slot, shadow));
        continue;
      }
      queries_->send(pe, e.owner, RayQuery{ray, slot, uint16_t(pe.id()), shadow});
      ++st.queriesSent;
      p.waiting = true;
      return;
    }
    resolve(pe, st, slot);
  }

  // On an owner: the nearest hit among the triangles of `bvh`, its own or its replicas (or
  // whether any occludes).
  HitReply answer(int pe, const Bvh& bvh, const Ray& ray, uint32_t slot, bool shadow) const {
    HitReply r;
    r.slot = slot;
    if (shadow) {
      r.found = bvh.occluded(ray);
    } else if (bvh.intersect(ray, r.hit)) {
      r.found = r.carriesHit = true;
      r.si = makeInteraction(views_.of(pe), ray, r.hit);
    }
    return r;
  }

  void answerRemote(par::Pe& pe, const RayQuery& q) {
    PeState& st = state_[pe.id()];
    HitReply r = answer(pe.id(), bvhs_[pe.id()], q.ray, q.slot, q.shadow);
    hits_->send(pe, q.origin, std::move(r));
    ++st.repliesSent;
  }

  static void merge(Pending& p, const HitReply& r) {
    if (r.found && (!p.best.found || r.hit.closerThan(p.best.hit))) p.best = r;
  }

  // On the originator: folds a reply into its record and asks on.
  void fold(par::Pe& pe, const HitReply& r) {
    PeState& st = state_[pe.id()];
    Pending& p = st.pending[r.slot];
    PR_CHECK(p.waiting, "object partitioning: reply for a ray that expects none");
    p.waiting = false;
    merge(p, r);
    ask(pe, st, r.slot);
  }

  // On the originator: shades the ray's closest hit (or its miss) and frees its record.
  void resolve(par::Pe& pe, PeState& st, uint32_t slot) {
    const Pending& p = st.pending[slot];
    Emit emit(*films_[size_t(pe.id())], st.spawned, st.stats, pe.id());
    if (!p.best.found)
      integrator_->miss(p.message, emit);  // unoccluded, or reaches no triangle
    else if (p.message.kind != RayKind::Shadow)
      integrator_->shade(p.best.si, p.message, emit);
    for (const RayMessage& s : st.spawned) {
      ++(s.kind == RayKind::Shadow ? st.stats.shadowRays : st.stats.continuationRays);
      st.start.push_back(s);
    }
    st.spawned.clear();
    st.freeSlots.push_back(slot);
    --st.live;
  }

  const TraceJob& job_;
  par::Runtime& rt_;
  uint32_t maxPieceTriangles_;
  double replicatedFraction_;
  ObjectAssignment assignment_;  // and directory_: made in the "split" stage
  OwnerDirectory directory_;      // derived by every PE's rank from the assignment
  size_t assignmentBytes_ = 0;    // the assignment's encoding: what PE 0 shares
  std::shared_ptr<const Integrator> integrator_;  // shade: one call per hit message handled
  std::vector<std::unique_ptr<Film>> films_;  // per PE: what it shaded; the assembler's is the image
  std::vector<Bvh> bvhs_;
  std::vector<Bvh> replicas_;  // per PE: its copy of the replicated pieces
  SceneViews views_;
  std::vector<PeState> state_;
  par::BatchedChannel<RayQuery>* queries_ = nullptr;
  par::BatchedChannel<HitReply>* hits_ = nullptr;
};

}  // namespace

TraceResult ObjectPartition::render(const TraceJob& job, par::Runtime& rt) {
  checkRayBatch(job.options, "object partitioning");
  ObjectFrame frame(job, rt, maxPieceTriangles_, replicatedFraction_);
  return frame.run();
}

std::unique_ptr<Partition> makeObjectPartition() { return std::make_unique<ObjectPartition>(); }

}  // namespace pr::rt
