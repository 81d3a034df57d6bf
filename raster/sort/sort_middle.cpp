// Sort-middle: the sort sits between geometry and rasterization. PEs transform and light
// their share of the scene triangles (geometry batches under the runtime's schedule), bin the
// screen triangles by region owner and send them as messages; each owner then rasterizes and
// shades its regions and delivers each finished one to the assembler (frame_assembly.h). The
// redistributed PDI is the 80-byte ScreenTriangle; the scene is replicated (world model).
#include <algorithm>

#include "common/parallel/channel.h"
#include "common/parallel/per_pe.h"
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

// One PE's counts of a frame, kept per PE while the stages run and put in the run record after
// them (Sort/triangles_*, sort_point.h).
struct Tally {
  uint64_t routed = 0, sent = 0, duplicated = 0;
};

void recordTallies(par::Runtime& rt, const par::PerPe<Tally>& tallies) {
  for (int p = 0; p < rt.pes(); ++p) {
    rt.addCounter("Sort/triangles_routed", p, double(tallies[p].routed));
    rt.addCounter("Sort/triangles_sent", p, double(tallies[p].sent));
    rt.addCounter("Sort/triangles_duplicated", p, double(tallies[p].duplicated));
  }
}

class SortMiddle : public SortPoint {
 public:
  std::string_view name() const override { return "sort-middle"; }
  bool runsAcrossRanks() const override { return true; }
  std::vector<ShadeCounters> takeShadeCounters() override {
    std::vector<ShadeCounters> out;
    for (int p = 0; p < drawers_.size(); ++p) out.push_back(drawers_[p].takeShadeCounters());
    return out;
  }

  void renderFrame(const FrameInputs& f, par::Runtime& rt, RegionFramebuffer& image) override {
    const int pes = rt.pes();
    const RegionGrid grid(f.view.width, f.view.height, f.options.regions, f.options.tileSizePx, pes,
                          shares_.forFrame(pes));
    const ShadingContext ctx = makeShadingContext(f.scene, f.view, f.options.effects, f.options.headlight);
    declareSortCounters(name(), rt);
    if (distribution_.firstFrame(f.scene, rt)) distributeReplicated(rt, f.scene);
    FrameAssembly frame(rt, image, pool_);
    if (grid.dynamic()) return renderDynamic(f, rt, grid, ctx, frame);
    par::PerPe<Tally> counters(pes);
    par::Channel<std::vector<ScreenTriangle>> triangles(rt, "screen triangles", par::MessageKind::Primitives);

    // Stage 1, geometry and the sort: one task per batch of scene triangles, on any PE.
    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const uint32_t batch = f.options.batchSize;
    const size_t batches = (total + batch - 1) / batch;
    rt.runStage("sort-middle geometry", par::TaskSet::uniform(batches), [&](par::Pe& pe, par::TaskId t) {
      const uint32_t first = static_cast<uint32_t>(t) * batch;
      std::vector<ScreenTriangle> tris;
      processTriangles(f.scene, f.view, first, std::min(batch, total - first), tris);
      Tally& c = counters[pe.id()];
      // One owner for the whole batch (always so at P = 1): the batch is the message as it is.
      std::vector<int> owner(tris.size());
      std::vector<char> scratch(pes, 0);
      std::vector<int> owners;
      bool single = true;
      for (size_t i = 0; i < tris.size(); ++i) {
        ownersOf(grid, pixelBounds(tris[i]), scratch, owners);
        c.routed += owners.size();
        if (owners.empty()) {
          owner[i] = -1;
          single = false;
          continue;
        }
        c.duplicated += owners.size() - 1;
        owner[i] = owners.size() == 1 ? owners[0] : pes;  // pes: several owners
        if (owner[i] != owner[0]) single = false;
      }
      if (tris.empty()) return;
      if (single && owner[0] < pes) {
        if (owner[0] != pe.id()) c.sent += tris.size();
        triangles.send(pe, owner[0], std::move(tris));
        return;
      }
      std::vector<std::vector<ScreenTriangle>> out(pes);
      for (size_t i = 0; i < tris.size(); ++i) {
        if (owner[i] < 0) continue;
        if (owner[i] < pes) {
          out[owner[i]].push_back(tris[i]);
          continue;
        }
        ownersOf(grid, pixelBounds(tris[i]), scratch, owners);
        for (int o : owners) out[o].push_back(tris[i]);
      }
      for (int o = 0; o < pes; ++o) {
        if (out[o].empty()) continue;
        if (o != pe.id()) c.sent += out[o].size();
        triangles.send(pe, o, std::move(out[o]));
      }
    });

    // Between stages the controlling thread hands each owner its mailbox.
    std::vector<std::vector<std::vector<ScreenTriangle>>> inbox(pes);
    for (int p = 0; p < pes; ++p) inbox[p] = triangles.drain(p);

    // Stage 2, rasterize and shade: each owner draws its regions from its own triangles and
    // delivers them to the assembler as they are finished.
    drawers_.resize(pes);
    rt.runOnEachPe("sort-middle rasterize", [&](par::Pe& pe) {
      const int p = pe.id();
      drawers_[p].draw(pe, ctx, inbox[p], grid, grid.regionsOf(p), frame);
    });
    describeTileCells(rt, grid);
    // Each rank measured its own PEs: the busy times summed across ranks are every PE's.
    std::vector<double> busy;
    for (const par::PeStageRecord& pe : rt.record().stages.back().pes) busy.push_back(pe.busySeconds);
    rt.sumAcrossRanks(busy);
    shares_.learn(grid, busy);
    recordTallies(rt, counters);
  }

 private:
  // Dynamic regions: each PE bins its screen triangles per tile and keeps them; tiles are then
  // handed out on demand and the PE taking a tile pulls that tile's bins from every PE.
  void renderDynamic(const FrameInputs& f, par::Runtime& rt, const RegionGrid& grid, const ShadingContext& ctx,
                     FrameAssembly& frame) {
    const int pes = rt.pes();
    const int tiles = grid.regionCount();
    par::PerPe<Tally> counters(pes);
    std::vector<std::vector<std::vector<ScreenTriangle>>> bins(pes, std::vector<std::vector<ScreenTriangle>>(tiles));

    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const uint32_t batch = f.options.batchSize;
    const size_t batches = (total + batch - 1) / batch;
    rt.runStage("sort-middle geometry", par::TaskSet::uniform(batches), [&](par::Pe& pe, par::TaskId t) {
      const uint32_t first = static_cast<uint32_t>(t) * batch;
      std::vector<ScreenTriangle> tris;
      processTriangles(f.scene, f.view, first, std::min(batch, total - first), tris);
      Tally& c = counters[pe.id()];
      for (const ScreenTriangle& tri : tris) {
        uint64_t n = 0;
        grid.forEachOverlapped(pixelBounds(tri), [&](int r) {
          bins[pe.id()][r].push_back(tri);
          ++n;
        });
        c.routed += n;
        if (n > 0) c.duplicated += n - 1;
      }
    });

    drawers_.resize(pes);
    {
      TilePull<std::vector<ScreenTriangle>> pull(rt, "sort-middle tile", bins);
      const par::TaskSet set = grid.regionTasks();
      rt.runStage("sort-middle rasterize", set, [&](par::Pe& pe, par::TaskId t) {
        std::vector<std::vector<ScreenTriangle>> parts = pull.gather(pe, static_cast<int>(t));
        std::vector<ScreenTriangle> tris = std::move(parts.front());
        for (size_t i = 1; i < parts.size(); ++i) tris.insert(tris.end(), parts[i].begin(), parts[i].end());
        drawers_[pe.id()].drawOne(pe, ctx, tris, grid.region(static_cast<int>(t)), frame);
      });
      for (int p = 0; p < pes; ++p) counters[p].sent += pull.itemsSent(p);
    }
    recordTallies(rt, counters);
  }

  par::PerPe<RegionDrawer> drawers_;  // per PE, kept between frames (binning storage)
  TileShares shares_;                 // static tiles per PE, from the last frame's draw times
  RegionBufferPool pool_;              // region message storage, kept between frames
  SceneDistribution distribution_;
};

}  // namespace

std::unique_ptr<SortPoint> makeSortMiddle() { return std::make_unique<SortMiddle>(); }

}  // namespace pr::raster
