// Sort-first: the sort sits before geometry. Scene primitives start on PEs in contiguous
// batches (or, from the second frame of a sequence, where the previous frame left them: frame
// coherence); each PE pre-transforms the primitives it holds just enough to find the screen
// regions they overlap and sends them to the region owners, who run the whole pipeline
// (geometry again, rasterize, shade) on their regions and deliver each finished region to the
// assembler (frame_assembly.h).
//
// What a primitive message carries. A distributed sort-first holds only its share of the
// geometry, so sending a primitive means sending its data: a message is a PrimitiveBatch, which
// leaves a rank as PrimitiveRecords (its id, index triple and material, and everything the
// stages read of its three vertices; common/scene/primitive_batch.h) and inside a rank names the
// primitives in the scene the rank loaded; it is counted as the records either way. The first
// frame sends each PE its initial share the same way (distributeShares) besides the replicated
// shading data. A PE whose geometry is its own (every PE under mpirun, and every PE under
// SortOptions::poisonForeignGeometry) reads only its copy of the scene, in which every vertex
// it was not given is NaN: its initial share, then each primitive it receives, installed from
// the message. In one process otherwise the PEs read the scene they share, in which the
// received primitives are the very bytes the messages carried. This makes sort-first's
// primitive traffic comparable with sort-middle's 80-byte ScreenTriangles.
#include <algorithm>
#include <numeric>
#include <memory>
#include <optional>
#include <span>

#include "common/parallel/channel.h"
#include "common/parallel/per_pe.h"
#include "common/scene/poisoned_view.h"
#include "common/util/error.h"
#include "raster/frame_assembly.h"
#include "raster/scene_distribution.h"
#include "raster/sort/bins.h"
#include "raster/sort/sort_point.h"
#include "raster/sort/tile_pull.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/shade.h"
#include "raster/stages/setup.h"

namespace pr::raster {
namespace {

// Geometry for a sorted list of primitive ids, appended in id order: runs of consecutive ids
// go through processTriangles (each shared vertex prepared once); the bits are the same as
// one primitive at a time (geometry.h).
void transformPrimitives(const scene::Scene& scene, const FrameView& view, std::span<const uint32_t> ids,
                         std::vector<ScreenTriangle>& out) {
  constexpr size_t kRun = 4096;
  for (size_t i = 0; i < ids.size();) {
    size_t j = i + 1;
    while (j < ids.size() && ids[j] == ids[j - 1] + 1 && j - i < kRun) ++j;
    processTriangles(scene, view, ids[i], static_cast<uint32_t>(j - i), out);
    i = j;
  }
}

// The union of the pixel bounds of the pieces of one primitive, grown by a piece.
void grow(Rect& b, const Rect& r) {
  if (r.empty()) return;
  b = b.empty() ? r : Rect{std::min(b.x0, r.x0), std::min(b.y0, r.y0), std::max(b.x1, r.x1), std::max(b.y1, r.y1)};
}

// Pixel bounds of every primitive of a sorted id list from its pieces (which come in id order):
// empty where it was culled or clipped away.
std::vector<Rect> boundsOfPieces(std::span<const uint32_t> ids, std::span<const ScreenTriangle> pieces) {
  std::vector<Rect> bounds(ids.size());
  size_t k = 0;
  for (const ScreenTriangle& t : pieces) {
    while (k < ids.size() && ids[k] != t.primitive) ++k;
    PR_CHECK(k < ids.size(), "sort-first: a piece of a primitive outside the list");
    grow(bounds[k], pixelBounds(t));
  }
  return bounds;
}

// The pre-transform: pixel bounds of all pieces of each primitive of a sorted id list (empty
// when it is culled or clipped away), by the same geometry function the owners run in full.
std::vector<Rect> primitiveBounds(const scene::Scene& scene, const FrameView& view, std::span<const uint32_t> ids) {
  std::vector<Rect> bounds;
  bounds.reserve(ids.size());
  std::vector<ScreenTriangle> pieces;
  constexpr size_t kChunk = 4096;
  for (size_t c0 = 0; c0 < ids.size(); c0 += kChunk) {
    const std::span<const uint32_t> chunk = ids.subspan(c0, std::min(kChunk, ids.size() - c0));
    pieces.clear();
    transformPrimitives(scene, view, chunk, pieces);
    const std::vector<Rect> b = boundsOfPieces(chunk, pieces);
    bounds.insert(bounds.end(), b.begin(), b.end());
  }
  return bounds;
}

// One PE's counts of a frame, kept per PE while the stages run and put in the run record after
// them (Sort/primitives_*, sort_point.h).
struct Tally {
  uint64_t routed = 0, sent = 0, duplicated = 0, migrated = 0, preTransforms = 0, geometryRepeated = 0;
};

void recordTallies(par::Runtime& rt, const par::PerPe<Tally>& tallies) {
  for (int p = 0; p < rt.pes(); ++p) {
    const Tally& t = tallies[p];
    rt.addCounter("Sort/primitives_routed", p, double(t.routed));
    rt.addCounter("Sort/primitives_sent", p, double(t.sent));
    rt.addCounter("Sort/primitives_duplicated", p, double(t.duplicated));
    rt.addCounter("Sort/primitives_migrated", p, double(t.migrated));
    rt.addCounter("Sort/pre_transforms", p, double(t.preTransforms));
    rt.addCounter("Sort/geometry_repeated", p, double(t.geometryRepeated));
  }
}

// The ids of the primitives of batches, appended to ids, then sorted and without repeats.
void addIds(std::span<const PrimitiveBatch> batches, std::vector<uint32_t>& ids) {
  for (const PrimitiveBatch& b : batches)
    for (size_t i = 0; i < b.size(); ++i) ids.push_back(b.id(i));
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
}

class SortFirst : public SortPoint {
 public:
  std::string_view name() const override { return "sort-first"; }
  bool runsAcrossRanks() const override { return true; }
  std::vector<ShadeCounters> takeShadeCounters() override {
    std::vector<ShadeCounters> out;
    for (int p = 0; p < drawers_.size(); ++p) out.push_back(drawers_[p].takeShadeCounters());
    return out;
  }

  void renderFrame(const FrameInputs& f, par::Runtime& rt, RegionFramebuffer& image) override {
    const int pes = rt.pes();
    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const RegionGrid grid(f.view.width, f.view.height, f.options.regions, f.options.tileSizePx, pes);
    const ShadingContext ctx = makeShadingContext(f.scene, f.view, f.options.effects, f.options.headlight);
    declareSortCounters(name(), rt);
    // The first frame on a scene and runtime hands every PE its initial share; each PE keeps
    // that share, so a later loss of coherence (below) starts again from it at no cost.
    const bool firstFrame = distribution_.firstFrame(f.scene, rt);
    if (firstFrame) distribute(f, rt);
    prepareShading(f, rt);
    FrameAssembly frame(rt, image, pool_);
    if (grid.dynamic()) {
      previous_.reset();  // no owner to keep primitives on between frames
      return renderDynamic(f, rt, grid, ctx, frame);
    }

    // Frame coherence holds only for the same scene, PE count and region assignment.
    const bool coherent = !firstFrame && previous_.has_value() && scene_ == &f.scene && triangles_ == total &&
                          previous_->grid.owners() == grid.owners() && held_.size() == size_t(pes) &&
                          previous_->view.width == f.view.width && previous_->view.height == f.view.height;
    if (!coherent) {
      // First frame: contiguous batches of primitive ids, one per PE.
      held_.assign(pes, {});
      for (int p = 0; p < pes; ++p) {
        const auto [lo, hi] = primitiveShare(total, p, pes);
        for (uint32_t i = lo; i < hi; ++i) held_[p].ids.push_back(i);
      }
      previous_.reset();
    }

    par::PerPe<Tally> counters(pes);
    std::vector<std::vector<uint32_t>> draw(pes);  // what each PE draws without a message
    std::vector<Held> unseen(pes);                 // what it keeps without drawing it
    par::Channel<PrimitiveBatch> primitives(rt, "scene primitives", par::MessageKind::Primitives);

    // Stage 1, pre-transform and the sort, each PE on the primitives it holds. A primitive held
    // by several PEs (it overlapped several owners last frame) is forwarded by one of them only:
    // the lowest of its previous owners (its primary); an unseen primitive has one holder. The
    // primary also counts a migration when the primitive's owner set differs from last frame's
    // (a new owner, a lost one, or entering or leaving the screen). Last frame's owners come
    // from the bounds each PE kept of what it held, so nothing is transformed twice.
    rt.runOnEachPe("sort-first pre-transform", [&](par::Pe& pe) {
      const int p = pe.id();
      Tally& c = counters[p];
      std::vector<PrimitiveBatch> out(pes, PrimitiveBatch{&f.scene, {}, {}});
      std::vector<char> scratch(pes, 0);
      std::vector<int> owners, before;
      const Held& held = held_[p];  // sorted by id
      const std::vector<Rect> now = primitiveBounds(geometryOf(f, p), f.view, held.ids);
      c.preTransforms += held.ids.size();
      for (size_t k = 0; k < held.ids.size(); ++k) {
        const uint32_t id = held.ids[k];
        ownersOf(grid, now[k], scratch, owners);
        before.clear();
        if (previous_) ownersOf(previous_->grid, held.bounds[k], scratch, before);
        const bool primary = before.empty() || before.front() == p;
        const bool ownNow = std::binary_search(owners.begin(), owners.end(), p);
        if (ownNow) {
          draw[p].push_back(id);
        } else if (primary && owners.empty()) {  // keeper of an unseen one: held, not drawn
          unseen[p].ids.push_back(id);
          unseen[p].bounds.push_back(now[k]);
        }
        if (!primary) continue;
        c.routed += owners.size();
        if (!owners.empty()) c.duplicated += owners.size() - 1;
        if (previous_ && owners != before) c.migrated += 1;
        for (int o : owners) {
          if (std::binary_search(before.begin(), before.end(), o)) continue;  // already holds it
          if (o == p) continue;
          out[o].ids.push_back(id);
          c.sent += 1;
        }
      }
      for (int o = 0; o < pes; ++o)
        if (out[o].size() > 0) primitives.send(pe, o, std::move(out[o]));
    });

    std::vector<std::vector<PrimitiveBatch>> received(pes);
    for (int p = 0; p < pes; ++p) received[p] = primitives.drain(p);

    // Stage 2, the whole pipeline on each owner's regions: geometry again on every primitive
    // it draws (those overlapping its regions), then rasterize and shade. What it draws and
    // what it keeps unseen are what it holds next frame, with their bounds in this frame.
    drawers_.resize(pes);
    std::vector<Held> next(pes);
    rt.runOnEachPe("sort-first render", [&](par::Pe& pe) {
      const int p = pe.id();
      std::vector<uint32_t>& mine = draw[p];
      install(p, received[p]);
      addIds(received[p], mine);
      std::vector<ScreenTriangle> tris;
      transformPrimitives(geometryOf(f, p), f.view, mine, tris);
      counters[p].geometryRepeated += mine.size();
      next[p] = merged(unseen[p], mine, boundsOfPieces(mine, tris));
      drawers_[p].draw(pe, shadingOf(p, ctx), std::span(&tris, 1), grid, grid.regionsOf(p), frame);
    });
    describeTileCells(rt, grid);

    held_ = std::move(next);
    previous_.emplace(Previous{f.view, grid});
    scene_ = &f.scene;
    triangles_ = total;
    recordTallies(rt, counters);
  }

 private:
  // The first frame: the shares leave PE 0 as records. A PE with geometry of its own (every PE
  // across ranks, or every PE under the poison check) starts from a copy of the scene in which
  // only its share is intact: PE 0's from the scene it loaded, the others' from the message.
  void distribute(const FrameInputs& f, par::Runtime& rt) {
    std::vector<PrimitiveBatch> shares = distributeShares(rt, f.scene, "sort-first distribute");
    views_.clear();
    views_.resize(size_t(rt.pes()));
    if (rt.ranks() == 1 && !f.options.poisonForeignGeometry) return;
    const auto [lo, hi] = primitiveShare(static_cast<uint32_t>(f.scene.triangles.size()), 0, rt.pes());
    std::vector<uint32_t> share0(hi - lo);
    std::iota(share0.begin(), share0.end(), lo);
    for (int p = rt.firstLocalPe(); p < rt.firstLocalPe() + rt.localPes(); ++p)
      views_[size_t(p)] = scene::shareView(f.scene, p, share0, {}, shares[size_t(p)]);
  }

  // The scene as PE p may read it: its own copy, or the scene the PEs share.
  const scene::Scene& geometryOf(const FrameInputs& f, int p) const {
    return views_.size() > size_t(p) && views_[size_t(p)] ? *views_[size_t(p)] : f.scene;
  }
  const ShadingContext& shadingOf(int p, const ShadingContext& shared) const {
    return shading_.size() > size_t(p) && shading_[size_t(p)] ? *shading_[size_t(p)] : shared;
  }
  // Shading reads vertex attributes (deferred): over the PE's own copy where it has one. Made
  // on the controlling thread; installing later primitives writes vertices in place.
  void prepareShading(const FrameInputs& f, par::Runtime& rt) {
    shading_.clear();
    shading_.resize(size_t(rt.pes()));
    for (int p = rt.firstLocalPe(); p < rt.firstLocalPe() + rt.localPes(); ++p)
      if (views_.size() > size_t(p) && views_[size_t(p)])
        shading_[size_t(p)].emplace(makeShadingContext(*views_[size_t(p)], f.view, f.options.effects, f.options.headlight));
  }
  // What PE p received goes into its copy of the scene (on p, or between stages).
  void install(int p, std::span<const PrimitiveBatch> batches) {
    if (views_.size() <= size_t(p) || !views_[size_t(p)]) return;
    for (const PrimitiveBatch& b : batches) installPrimitives(*views_[size_t(p)], b);
  }

  // Dynamic regions: each PE pre-transforms its contiguous share and keeps the primitives
  // binned per tile; tiles are handed out on demand and the PE taking a tile pulls them from
  // every PE and runs the whole pipeline on that tile (so a primitive's geometry runs once per
  // tile).
  void renderDynamic(const FrameInputs& f, par::Runtime& rt, const RegionGrid& grid, const ShadingContext& ctx,
                     FrameAssembly& frame) {
    const int pes = rt.pes();
    const int tiles = grid.regionCount();
    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    par::PerPe<Tally> counters(pes);
    std::vector<std::vector<PrimitiveBatch>> bins(pes, std::vector<PrimitiveBatch>(tiles, PrimitiveBatch{&f.scene, {}, {}}));
    rt.runOnEachPe("sort-first pre-transform", [&](par::Pe& pe) {
      const int p = pe.id();
      Tally& c = counters[p];
      const auto [lo, hi] = primitiveShare(total, p, pes);
      std::vector<uint32_t> held(hi - lo);
      std::iota(held.begin(), held.end(), lo);
      const std::vector<Rect> bounds = primitiveBounds(geometryOf(f, p), f.view, held);
      for (size_t k = 0; k < held.size(); ++k) {
        uint64_t n = 0;
        grid.forEachOverlapped(bounds[k], [&](int r) {
          bins[p][r].ids.push_back(held[k]);
          ++n;
        });
        c.preTransforms += 1;
        c.routed += n;
        if (n > 0) c.duplicated += n - 1;
      }
    });

    drawers_.resize(pes);
    {
      TilePull<PrimitiveBatch> pull(rt, "sort-first tile", bins);
      const par::TaskSet set = grid.regionTasks();
      rt.runStage("sort-first render", set, [&](par::Pe& pe, par::TaskId t) {
        const std::vector<PrimitiveBatch> parts = pull.gather(pe, static_cast<int>(t));
        install(pe.id(), parts);
        std::vector<uint32_t> ids;
        addIds(parts, ids);  // id order, for runs of ids
        std::vector<ScreenTriangle> tris;
        transformPrimitives(geometryOf(f, pe.id()), f.view, ids, tris);
        counters[pe.id()].geometryRepeated += ids.size();
        drawers_[pe.id()].drawOne(pe, shadingOf(pe.id(), ctx), tris, grid.region(static_cast<int>(t)), frame);
      });
      for (int p = 0; p < pes; ++p) counters[p].sent += pull.itemsSent(p);
    }
    recordTallies(rt, counters);
  }

  struct Previous {
    FrameView view;
    RegionGrid grid;
  };
  // The primitives a PE holds, sorted by id, with their pixel bounds in the previous frame
  // (none on a frame that starts from the initial shares).
  struct Held {
    std::vector<uint32_t> ids;
    std::vector<Rect> bounds;
  };
  // Two disjoint held lists, each sorted by id, as one.
  static Held merged(const Held& a, std::span<const uint32_t> ids, std::span<const Rect> bounds) {
    Held out;
    out.ids.reserve(a.ids.size() + ids.size());
    out.bounds.reserve(out.ids.capacity());
    size_t i = 0, j = 0;
    while (i < a.ids.size() || j < ids.size()) {
      const bool fromA = j == ids.size() || (i < a.ids.size() && a.ids[i] < ids[j]);
      out.ids.push_back(fromA ? a.ids[i] : ids[j]);
      out.bounds.push_back(fromA ? a.bounds[i++] : bounds[j++]);
    }
    return out;
  }
  par::PerPe<RegionDrawer> drawers_;  // per PE, kept between frames (binning storage)
  RegionBufferPool pool_;              // region message storage, kept between frames
  SceneDistribution distribution_;
  // Per PE of this rank, its own copy of the scene (see the top), kept between frames; null
  // where the PEs share the scene.
  std::vector<std::unique_ptr<scene::Scene>> views_;
  std::vector<std::optional<ShadingContext>> shading_;  // per PE, over its copy, this frame
  // Between frames: the primitives each PE holds, and the view and regions they were sorted by.
  std::vector<Held> held_;
  std::optional<Previous> previous_;
  const scene::Scene* scene_ = nullptr;
  uint32_t triangles_ = 0;
};

}  // namespace

std::unique_ptr<SortPoint> makeSortFirst() { return std::make_unique<SortFirst>(); }

}  // namespace pr::raster
