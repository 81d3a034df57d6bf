// The image-space tracer with a data manager. Stage "build": each owner makes the data items of
// its pieces (a BVH over the piece's triangles, built against the scene's vertex positions, and
// a small scene of the piece's vertex data for interactions). Stage "trace": image tiles are
// tasks under any schedule; each ray is traced by the PE that runs its tile. The closest hit is
// found over the items the ray reaches, nearest first (the replicated item directory, with the
// closest hit so far as the next query's tMax), each item taken through the DataManager; a
// shadow ray stops at the first item with an occluder. The interaction is made from the item
// that holds the hit, so no PE reads geometry it neither owns nor fetched (the poisoned-view
// check of the tests). Finished tiles travel to the assembler as in image-space.
//
// Profiling (seed section 4.5.3): a PE notes the items each of its tiles used, and before a tile
// prefetches what its own finished tiles next to it used (spatial coherence), falling back to
// the items every 16th camera ray reaches first when it has none nearby. Under a schedule that
// needs cost estimates (unbalanced, hot-spots) a low-resolution profile pre-pass traces every
// fourth pixel of each tile through the data manager first: its rays per tile are the costs,
// and each PE keeps the items its pre-pass tiles used as the start of its profile.
//
// A fetched item is the owner's immutable item: inside a rank handed over by reference, to
// another rank sent as its encoding (the BVH's nodes and leaf blocks, the piece's vertex data
// and triangles; Wire<ItemRef> below), counted as that encoding's size either way; the cache
// bounds how many bytes of other PEs' items a PE may use without asking again. Across ranks
// every rank makes the assignment and the item directory alike; the owners build their items
// from their own view of the scene, and the items' sizes are summed across ranks, so every PE
// knows every item's size as in one process.
#include "raytrace/partition/cached_image_space.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/parallel/data_manager.h"
#include "common/parallel/schedulers/scheduler.h"
#include "raytrace/partition/film_assembly.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/owner_directory.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/partitioned.h"

namespace pr::rt {
namespace {

// One data item: a piece's BVH (its triangles' vertices are inside it; hits report scene
// triangle indices) and the vertex data interactions read, as a scene of the piece alone.
struct GeometryItem {
  Bvh bvh;
  scene::Scene local;              // the piece's vertices and triangles, renumbered; all materials
  std::vector<uint32_t> triangles;  // scene index of local triangle i, ascending
  std::size_t bytes = 0;

  // The interaction at a hit of this item's BVH, bit for bit the one the whole scene gives.
  SurfaceInteraction interaction(const Ray& ray, const Hit& hit) const {
    const auto it = std::lower_bound(triangles.begin(), triangles.end(), hit.triangle);
    PR_CHECK(it != triangles.end() && *it == hit.triangle, "image-space-cached: a hit outside its item");
    SurfaceInteraction si = makeInteraction(local, ray, Hit{hit.t, uint32_t(it - triangles.begin()), hit.u, hit.v});
    si.triangle = hit.triangle;
    return si;
  }
};
using ItemRef = std::shared_ptr<const GeometryItem>;

// The size of an item's encoding: its BVH's, then each vertex array and the two triangle lists
// as sequences (a count, then the elements).
std::size_t encodedBytes(const GeometryItem& g) {
  const scene::Scene& l = g.local;
  const auto seq = [](std::size_t n, std::size_t element) { return sizeof(uint64_t) + n * element; };
  return g.bvh.encodedBytes() + seq(l.positions.size(), sizeof(glm::vec3)) + seq(l.normals.size(), sizeof(glm::vec3)) +
         seq(l.uvs.size(), sizeof(glm::vec2)) + seq(l.colors.size(), sizeof(glm::vec4)) +
         seq(l.tangents.size(), sizeof(glm::vec4)) + seq(l.triangles.size(), sizeof(scene::Triangle)) +
         seq(g.triangles.size(), sizeof(uint32_t));
}

void encodeItem(const GeometryItem& g, par::WireWriter& w) {
  const scene::Scene& l = g.local;
  w.reserve(g.bytes);
  g.bvh.encode(w);
  w.sequence(std::span<const glm::vec3>(l.positions));
  w.sequence(std::span<const glm::vec3>(l.normals));
  w.sequence(std::span<const glm::vec2>(l.uvs));
  w.sequence(std::span<const glm::vec4>(l.colors));
  w.sequence(std::span<const glm::vec4>(l.tangents));
  w.sequence(std::span<const scene::Triangle>(l.triangles));
  w.sequence(std::span<const uint32_t>(g.triangles));
}

// An item that arrived from another rank, completed from the receiver's own copy of the
// scene: its materials (replicated) and the alpha test its BVH cuts surfaces with.
ItemRef decodeItem(par::WireReader& r, const scene::Scene& s, std::shared_ptr<const AlphaTest> alpha) {
  auto item = std::make_shared<GeometryItem>();
  item->bvh = Bvh::decode(r, std::move(alpha));
  scene::Scene& l = item->local;
  l.positions = r.sequence<glm::vec3>();
  l.normals = r.sequence<glm::vec3>();
  l.uvs = r.sequence<glm::vec2>();
  l.colors = r.sequence<glm::vec4>();
  l.tangents = r.sequence<glm::vec4>();
  l.triangles = r.sequence<scene::Triangle>();
  item->triangles = r.sequence<uint32_t>();
  // Checked, not trusted: what the interaction reads must be there.
  for (const std::size_t n : {l.normals.size(), l.uvs.size(), l.colors.size(), l.tangents.size()})
    if (n != 0 && n != l.positions.size()) throw par::WireError("a geometry item's vertex arrays differ in length");
  for (const scene::Triangle& t : l.triangles) {
    if (t.material >= s.materials.size()) throw par::WireError("a geometry item's triangle names a material the scene lacks");
    for (uint32_t v : t.v)
      if (v >= l.positions.size()) throw par::WireError("a geometry item's triangle names a vertex it does not hold");
  }
  if (item->triangles.size() != l.triangles.size() || !std::is_sorted(item->triangles.begin(), item->triangles.end()))
    throw par::WireError("a geometry item's scene triangle list is not one ascending entry per triangle");
  l.materials = s.materials;
  item->bytes = encodedBytes(*item);
  return item;
}

}  // namespace
}  // namespace pr::rt

namespace pr::par {
// Decoding needs the receiver's scene: the data manager decodes items with decodeItem
// (DataManager::decodeItemsWith); Wire gives the size and the encoding.
template <>
struct Wire<rt::ItemRef> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const rt::ItemRef& item) { return item ? item->bytes : 0; }
  static void encode(const rt::ItemRef& item, WireWriter& w) { rt::encodeItem(*item, w); }
  static rt::ItemRef decode(WireReader&) {
    throw std::logic_error("a geometry item is decoded against the receiver's scene (DataManager::decodeItemsWith)");
  }
};
}  // namespace pr::par

namespace pr::rt {
namespace {

// The item of piece `tris` from scene s (the owner's view of the scene).
ItemRef makeItem(const scene::Scene& s, std::span<const uint32_t> tris, const BvhBuildOptions& options) {
  auto item = std::make_shared<GeometryItem>();
  item->bvh = Bvh(s.positions, s.triangles, tris, options);
  item->triangles.assign(tris.begin(), tris.end());
  scene::Scene& l = item->local;
  l.materials = s.materials;  // the anisotropy test of makeInteraction reads the material
  std::vector<uint32_t> renumber(s.positions.size(), UINT32_MAX);
  auto copyVertex = [&](uint32_t v) {
    if (renumber[v] != UINT32_MAX) return renumber[v];
    renumber[v] = uint32_t(l.positions.size());
    l.positions.push_back(s.positions[v]);
    if (s.normals.size() == s.positions.size()) l.normals.push_back(s.normals[v]);
    if (s.uvs.size() == s.positions.size()) l.uvs.push_back(s.uvs[v]);
    if (s.colors.size() == s.positions.size()) l.colors.push_back(s.colors[v]);
    if (s.tangents.size() == s.positions.size()) l.tangents.push_back(s.tangents[v]);
    return renumber[v];
  };
  for (uint32_t t : tris) {
    scene::Triangle tri = s.triangles[t];
    for (uint32_t& v : tri.v) v = copyVertex(v);
    l.triangles.push_back(tri);
  }
  item->bytes = encodedBytes(*item);
  return item;
}

// What a data item holds and who owns it: consecutive pieces of one owner along the Morton
// curve, gathered until the item holds about total / (kItemsPerPe P) triangles, so a PE's
// geometry is a few spatially compact items (a ray walks few of them, each a deep BVH).
constexpr uint32_t kItemsPerPe = 8;
struct ItemSpec {
  int owner = 0;
  std::vector<uint32_t> triangles;  // ascending scene indices
  scene::Bounds bounds;
};

std::vector<ItemSpec> groupPieces(const ObjectAssignment& a, size_t totalTriangles) {
  const size_t target = std::max<size_t>(64, totalTriangles / (size_t(kItemsPerPe) * size_t(a.pes())));
  std::vector<ItemSpec> items;
  for (uint32_t p : a.curveOrder()) {
    const ObjectPiece& piece = a.pieces()[p];
    if (items.empty() || items.back().owner != piece.owner || items.back().triangles.size() >= target)
      items.push_back(ItemSpec{piece.owner, {}, {}});
    ItemSpec& item = items.back();
    item.triangles.insert(item.triangles.end(), piece.triangles.begin(), piece.triangles.end());
    item.bounds.extend(piece.bounds);
  }
  for (ItemSpec& item : items) std::sort(item.triangles.begin(), item.triangles.end());
  return items;
}

// The job's BVH options with the scene's alpha test (renderRays sets it; a direct render() call
// may not), so that every item's BVH cuts the same surfaces as the sequential tracer's.
BvhBuildOptions withAlpha(BvhBuildOptions options, const scene::Scene& s) {
  if (!options.alpha) options.alpha = AlphaTest::forScene(s);
  return options;
}

class CachedImageSpaceFrame {
 public:
  CachedImageSpaceFrame(const TraceJob& job, par::Runtime& rt)
      : job_(job),
        rt_(rt),
        assignment_(job.scene, {rt.pes(), 0, partitionMargin(job.scene, job.camera.position())}),
        specs_(groupPieces(assignment_, job.scene.triangles.size())),
        directory_(itemBounds(specs_), assignment_.margin()),
        integrator_(jobIntegrator(job)),
        bvhOptions_(withAlpha(job.options.bvh, job.scene)),
        items_(specs_.size()),
        itemBytes_(specs_.size(), 0),
        views_(job, rt),
        state_(size_t(rt.pes())) {}

  TraceResult run() {
    const int pes = rt_.pes();
    // Each owner's triangles leave PE 0 as messages; an owner builds its items from them.
    const auto heldBy = [&](int p) {
      return std::vector<uint32_t>(assignment_.triangles(p).begin(), assignment_.triangles(p).end());
    };
    const std::vector<scene::PrimitiveBatch> received = scene::sendPrimitiveShares(rt_, job_.scene, job_.stage("distribute"), heldBy);
    rt_.runOnEachPe(job_.stage("build"), [&](par::Pe& pe) {
      views_.build(pe.id(), heldBy(pe.id()), integrator_->context().lights(), received[size_t(pe.id())]);
      for (size_t i = 0; i < specs_.size(); ++i)
        if (specs_[i].owner == pe.id()) {
          items_[i] = makeItem(views_.of(pe.id()), specs_[i].triangles, bvhOptions_);
          itemBytes_[i] = items_[i]->bytes;
        }
    });
    // Across ranks a rank built its own PEs' items: every item's size, summed across ranks,
    // is known everywhere (the directory's sizes: replicated, as in one process).
    std::vector<double> sizes(itemBytes_.begin(), itemBytes_.end());
    rt_.sumAcrossRanks(sizes);
    for (size_t i = 0; i < sizes.size(); ++i) itemBytes_[i] = std::size_t(sizes[i]);

    std::vector<int> owners;
    for (const ItemSpec& item : specs_) owners.push_back(item.owner);
    par::DataManager<ItemRef> data(
        rt_, "geometry", par::OwnerMap(std::move(owners)), SIZE_MAX,
        [this](par::Pe& owner, par::ItemId id) {
          PR_CHECK(specs_[id].owner == owner.id(), "image-space-cached: an item served by a PE that does not own it");
          return items_[id];
        },
        [](const ItemRef& item) { return item->bytes; }, job_.options.cacheBytes);
    data.setLatency(job_.options.dataLatencySeconds);
    data.decodeItemsWith([this](par::WireReader& r) { return decodeItem(r, job_.scene, bvhOptions_.alpha); });
    data_ = &data;

    const std::vector<PixelRect> tiles = cameraTiles(job_.width, job_.height, job_.options.tileSizePx);
    for (PeState& st : state_) st.profile.assign(tiles.size(), {});
    par::TaskSet tasks = tileTaskSet(tiles, job_.options.tileSizePx);
    // A pre-pass program gets no profile pre-pass: it would run the program's side effects twice.
    if (job_.assembleImage && par::scheduleNeedsCostEstimates(rt_.options().schedule)) profilePrePass(tiles, tasks);
    Film film(job_.filmWidth(), job_.filmHeight(), integrator_->options().spp);
    FilmAssembly assembly(rt_, film);
    // Materials, textures, lights, the emitters and the item directory (bounds, owner and size
    // of every item) are replicated; the geometry items are not.
    recordReplicatedData(rt_, job_, integrator_->context().lights(),
                         directory_.bytes() + specs_.size() * (sizeof(int) + sizeof(uint64_t)), 0);
    std::atomic<int64_t> done{0};
    const auto total = int64_t(tiles.size());
    rt_.runStage(job_.stage("trace"), tasks, [&](par::Pe& pe, par::TaskId id) {
      PeState& st = state_[size_t(pe.id())];
      const PixelRect& rect = tiles[size_t(id)];
      Film tile(rect, job_.width, job_.height, integrator_->options().spp);
      integrator_->cameraRays(rect, st.queue);
      countStartRays(st.stats, st.queue);
      prefetch(pe, st, tiles, size_t(id));
      traceTile(pe, st, tile, st.stats);
      noteProfile(st, size_t(id), true);
      if (job_.assembleImage) assembly.deliver(pe, tile, rect, false);
      const int64_t n = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (job_.options.progress) job_.options.progress(n, total);
    });
    data_ = nullptr;

    PartitionHoldings held;
    std::vector<TraceStats> raysTraced;
    for (int p = 0; p < pes; ++p) {
      uint64_t bytes = 0, owned = 0, largest = 0;
      for (size_t i = 0; i < specs_.size(); ++i)
        if (specs_[i].owner == p) {
          bytes += itemBytes_[i];
          largest = std::max<uint64_t>(largest, itemBytes_[i]);
          ++owned;
        }
      rt_.addCounter("Cache/largest_item_bytes", p, double(largest));
      held.geometryBytes.push_back(bytes);
      held.triangles.push_back(assignment_.triangles(p).size());
      held.partitionsOwned.push_back(owned);
      const PeState& st = state_[size_t(p)];
      raysTraced.push_back(st.stats);
      rt_.addCounter("Cache/capacity_bytes", p, double(job_.options.cacheBytes));
      rt_.addCounter("Cache/hits", p, double(data.hits(p)));
      rt_.addCounter("Cache/misses", p, double(data.misses(p)));
      rt_.addCounter("Cache/misses_joined", p, double(data.joined(p)));
      rt_.addCounter("Cache/prefetches", p, double(st.prefetched));
      rt_.addCounter("Cache/prefetches_from_profile", p, double(st.prefetchedFromProfile));
      rt_.addCounter("Cache/prefetches_used", p, double(st.prefetchesUsed));
      rt_.addCounter("Cache/own_item_uses", p, double(st.ownUses));
      rt_.addCounter("Cache/bytes_held_at_end", p, double(data.cache(p).usedBytes()));
    }
    recordPartitionHoldings(held, rt_);
    return TraceResult{film.toImage(), recordRayCounters(rt_, raysTraced), tiles.size()};
  }

 private:
  // Padded to a cache line: each PE writes only its own.
  struct alignas(64) PeState {
    std::vector<RayMessage> queue;
    std::vector<OwnerDirectory::NodeEntry> heap;
    std::vector<par::ItemId> wanted;   // the current tile's prefetch
    std::vector<par::ItemId> touched;  // items the current tile used, own ones included
    // Per tile, if this PE ran it: the items it used and how often, by item.
    std::vector<std::vector<std::pair<par::ItemId, uint32_t>>> profile;
    std::vector<std::pair<par::ItemId, uint32_t>> votes;  // scratch of the prediction
    TraceStats stats;
    uint64_t prefetched = 0, prefetchedFromProfile = 0, prefetchesUsed = 0, ownUses = 0;
  };

  static std::vector<scene::Bounds> itemBounds(const std::vector<ItemSpec>& items) {
    std::vector<scene::Bounds> boxes;
    for (const ItemSpec& item : items) boxes.push_back(item.bounds);
    return boxes;
  }

  // Before tile `id`: the items the PE's own finished tiles around it used most (its profile),
  // as many as fill half its cache (a prediction that evicts what the tile needs costs more
  // than it saves), or without any, the items every 16th of its camera rays reaches first;
  // fetched at once (one request each, the replies awaited together).
  void prefetch(par::Pe& pe, PeState& st, const std::vector<PixelRect>& tiles, size_t id) {
    const int ts = job_.options.tileSizePx;
    const int cols = (job_.width + ts - 1) / ts;
    const int col = tiles[id].x0 / ts, row = tiles[id].y0 / ts;
    st.wanted.clear();
    st.touched.clear();
    const TraceOptions::Prefetch mode = job_.options.prefetch;
    if (mode == TraceOptions::Prefetch::None) return;
    // Not its own, not cached already, and small enough to be kept (a prefetched item the
    // cache cannot hold would be fetched again at its use).
    auto useless = [&](par::ItemId item) {
      return data_->owner(item) == pe.id() || data_->cache(pe.id()).contains(item) ||
             itemBytes_[item] > job_.options.cacheBytes;
    };
    st.votes.clear();
    for (int r = row - 1; mode == TraceOptions::Prefetch::Profile && r <= row + 1; ++r)
      for (int c = col - 1; c <= col + 1; ++c) {
        const size_t n = size_t(r) * size_t(cols) + size_t(c);
        if (r < 0 || c < 0 || c >= cols || n >= tiles.size()) continue;
        st.votes.insert(st.votes.end(), st.profile[n].begin(), st.profile[n].end());
      }
    const bool profiled = !st.votes.empty();
    if (profiled) {
      std::sort(st.votes.begin(), st.votes.end());
      std::vector<std::pair<uint64_t, par::ItemId>> ranked;  // (uses, item), most used first
      for (size_t i = 0; i < st.votes.size();) {
        uint64_t uses = 0;
        const par::ItemId item = st.votes[i].first;
        for (; i < st.votes.size() && st.votes[i].first == item; ++i) uses += st.votes[i].second;
        if (!useless(item)) ranked.emplace_back(uses, item);
      }
      std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
      });
      uint64_t bytes = 0;
      for (const auto& [uses, item] : ranked) {
        if (bytes + itemBytes_[item] > job_.options.cacheBytes / 2) break;
        bytes += itemBytes_[item];
        st.wanted.push_back(item);
      }
    } else {
      constexpr size_t kStride = 16;
      for (size_t i = 0; i < st.queue.size(); i += kStride) {
        OwnerDirectory::NearestFirst walk(directory_, st.queue[i].ray, -1, st.heap);
        OwnerEntry e;
        if (walk.next(kInfinity, e)) st.wanted.push_back(par::ItemId(e.owner));
      }
      std::sort(st.wanted.begin(), st.wanted.end());
      st.wanted.erase(std::unique(st.wanted.begin(), st.wanted.end()), st.wanted.end());
      std::erase_if(st.wanted, useless);
    }
    st.prefetched += st.wanted.size();
    if (profiled) st.prefetchedFromProfile += st.wanted.size();
    data_->prefetch(pe, st.wanted);
  }

  // After tile `id`: the items it used, with their use counts, become its profile entry; with
  // `countPrefetches`, the prefetched items it used are counted (Cache/prefetches_used).
  static void noteProfile(PeState& st, size_t id, bool countPrefetches) {
    std::sort(st.touched.begin(), st.touched.end());
    std::vector<std::pair<par::ItemId, uint32_t>>& entry = st.profile[id];
    entry.clear();
    for (par::ItemId item : st.touched) {
      if (!entry.empty() && entry.back().first == item) ++entry.back().second;
      else entry.emplace_back(item, 1);
    }
    if (countPrefetches)
      for (par::ItemId w : st.wanted)
        st.prefetchesUsed += std::binary_search(st.touched.begin(), st.touched.end(), w);
  }

  // The profile pre-pass (its own stage, balanced split, measured with the render): every
  // fourth pixel in x and y of each tile, one sample, traced through the data manager into a
  // scratch film. Rays traced per sampled pixel, scaled to the tile's pixel count, become the
  // tile's cost for the schedule; the items it used start the PE's profile. Its rays are not
  // the render's: they are not in the ray counters.
  void profilePrePass(const std::vector<PixelRect>& tiles, par::TaskSet& tasks) {
    const std::unique_ptr<par::Scheduler> balanced = par::makeScheduler("balanced");
    std::vector<double> costs(tiles.size(), 0.0);
    rt_.runStage(job_.stage("profile pre-pass"), par::TaskSet::uniform(tiles.size()), *balanced,
                 [&](par::Pe& pe, par::TaskId id) {
                   PeState& st = state_[size_t(pe.id())];
                   const PixelRect& rect = tiles[size_t(id)];
                   Film scratch(rect, job_.width, job_.height, 1);
                   TraceStats stats;
                   int64_t sampled = 0;
                   for (int y = rect.y0; y < rect.y1; y += kCostPrePassStride)
                     for (int x = rect.x0; x < rect.x1; x += kCostPrePassStride) {
                       integrator_->cameraRays(PixelRect{x, y, x + 1, y + 1}, 1, st.queue);
                       ++sampled;
                     }
                   countStartRays(stats, st.queue);
                   st.wanted.clear();
                   st.touched.clear();
                   traceTile(pe, st, scratch, stats);
                   noteProfile(st, size_t(id), false);
                   costs[size_t(id)] = tileCostEstimate(stats.total(), rect, sampled);
                 });
    // Across ranks a rank estimated its own PEs' tiles: summed, every rank deals the same tasks.
    rt_.sumAcrossRanks(costs);
    for (size_t i = 0; i < costs.size(); ++i) tasks.tasks[i].costEstimate = costs[i];
  }

  // A ray of the tile, with its walk through the item directory so far: parked at an item that
  // is on its way, it resumes there, so every arrival advances the rays that waited for it (no
  // ray restarts, none can starve, whatever the cache size).
  struct WalkingRay {
    explicit WalkingRay(const RayMessage& m) : message(m) {}
    RayMessage message;
    std::vector<OwnerDirectory::NodeEntry> heap;
    bool started = false;
    bool parked = false;  // `at` is the item it waits for, already taken from the walk
    OwnerEntry at;
    Hit best;
    bool found = false;
    SurfaceInteraction si;
  };

  // The tile's rays and all they spawn, depth first. With latency hiding they are threads (seed
  // section 4.5.2): a ray that needs an item on its way is parked and the PE goes on with the
  // tile's other rays; only when every ray waits does it wait for the next arrival, and then
  // resumes the rays that waited for that item. Without, a ray waits for its item in place.
  void traceTile(par::Pe& pe, PeState& st, Film& film, TraceStats& stats) {
    std::vector<WalkingRay> ready;
    std::unordered_map<par::ItemId, std::vector<WalkingRay>> parked;
    size_t waiting = 0;
    for (const RayMessage& m : st.queue) ready.emplace_back(m);
    st.queue.clear();
    std::vector<RayMessage> spawned;
    Emit emit(film, spawned, stats, pe.id());
    for (;;) {
      if (ready.empty()) {
        if (waiting == 0) return;
        const par::ItemId arrived = data_->awaitArrival(pe);
        auto it = parked.find(arrived);
        if (it == parked.end()) continue;  // a prefetch's or an earlier ray's request
        waiting -= it->second.size();
        for (WalkingRay& w : it->second) ready.push_back(std::move(w));
        parked.erase(it);
        continue;
      }
      WalkingRay w = std::move(ready.back());
      ready.pop_back();
      if (!step(pe, st, w)) {
        const auto item = par::ItemId(w.at.owner);
        parked[item].push_back(std::move(w));
        ++waiting;
        continue;
      }
      const RayMessage& m = w.message;
      if (m.kind == RayKind::Shadow) {
        if (!w.found) integrator_->miss(m, emit);
      } else if (w.found) {
        integrator_->shade(w.si, m, emit);
      } else {
        integrator_->miss(m, emit);
      }
      for (const RayMessage& r : spawned) {
        ++(r.kind == RayKind::Shadow ? stats.shadowRays : stats.continuationRays);
        ready.emplace_back(r);
      }
      spawned.clear();
    }
  }

  // Walks the ray on through the items until it is done (true; for a shadow ray `found` means
  // occluded) or, with latency hiding, needs an item that is not here (false: parked at `at`,
  // its request sent).
  bool step(par::Pe& pe, PeState& st, WalkingRay& w) {
    const bool shadow = w.message.kind == RayKind::Shadow;
    OwnerDirectory::NearestFirst walk(directory_, w.message.ray, -1, w.heap, w.started);
    w.started = true;
    for (;;) {
      bool resumed = false;
      if (w.parked) {
        w.parked = false;
        resumed = true;
      } else if (!walk.next(w.found && !shadow ? w.best.t : kInfinity, w.at)) {
        return true;
      }
      const auto id = par::ItemId(w.at.owner);
      const GeometryItem* g = nullptr;
      if (specs_[id].owner == pe.id()) {
        ++st.ownUses;
        g = items_[id].get();
      } else if (!job_.options.hideLatency) {
        g = data_->acquire(pe, id).get();
      } else if (const ItemRef* ref = data_->tryAcquire(pe, id, !resumed)) {
        g = ref->get();
      } else {
        w.parked = true;
        return false;
      }
      st.touched.push_back(id);
      if (shadow) {
        if (g->bvh.occluded(w.message.ray)) {
          w.found = true;
          return true;
        }
        continue;
      }
      Ray bounded = w.message.ray;
      if (w.found) bounded.tMax = w.best.t;  // inclusive: an equal t with a lower triangle still wins
      Hit h;
      if (!g->bvh.intersect(bounded, h) || (w.found && !h.closerThan(w.best))) continue;
      w.best = h;
      w.found = true;
      w.si = g->interaction(w.message.ray, h);
    }
  }

  const TraceJob& job_;
  par::Runtime& rt_;
  ObjectAssignment assignment_;
  std::vector<ItemSpec> specs_;
  OwnerDirectory directory_;  // over the items, replicated
  std::shared_ptr<const Integrator> integrator_;
  BvhBuildOptions bvhOptions_;
  std::vector<ItemRef> items_;  // item i, made and read only by its owner (others fetch it)
  std::vector<uint64_t> itemBytes_;  // part of the directory: every item's size
  SceneViews views_;
  std::vector<PeState> state_;
  par::DataManager<ItemRef>* data_ = nullptr;
};

}  // namespace

TraceResult CachedImageSpacePartition::render(const TraceJob& job, par::Runtime& rt) {
  CachedImageSpaceFrame frame(job, rt);
  return frame.run();
}

std::unique_ptr<Partition> makeCachedImageSpacePartition() { return std::make_unique<CachedImageSpacePartition>(); }

}  // namespace pr::rt
