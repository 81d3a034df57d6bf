// Sort-middle: the sort sits between geometry and rasterization. PEs transform and light
// their share of the scene triangles (geometry batches under the runtime's schedule), bin the
// screen triangles by region owner and send them as messages; each owner then rasterizes and
// shades its regions. The redistributed PDI is the 80-byte ScreenTriangle.
#include <algorithm>

#include "common/parallel/channel.h"
#include "raster/sort/bins.h"
#include "raster/sort/sort_point.h"
#include "raster/sort/tile_pull.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/shade.h"
#include "raster/stages/setup.h"

namespace pr::raster {
namespace {

class SortMiddle : public SortPoint {
 public:
  std::string_view name() const override { return "sort-middle"; }

  SortCounters renderFrame(const FrameInputs& f, par::Runtime& rt, RegionFramebuffer& image) override {
    const int pes = rt.pes();
    const RegionGrid grid(f.view.width, f.view.height, f.options.regions, f.options.tileSizePx, pes);
    const ShadingContext ctx = makeShadingContext(f.scene, f.view);
    if (grid.dynamic()) return renderDynamic(f, rt, grid, ctx, image);
    std::vector<SortCounters> counters(pes);
    par::Channel<std::vector<ScreenTriangle>> triangles(rt, "screen triangles");

    // Stage 1, geometry and the sort: one task per batch of scene triangles, on any PE.
    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const uint32_t batch = f.options.batchSize;
    const size_t batches = (total + batch - 1) / batch;
    rt.runStage("sort-middle geometry", par::TaskSet::uniform(batches), [&](par::Pe& pe, par::TaskId t) {
      const uint32_t first = static_cast<uint32_t>(t) * batch;
      std::vector<ScreenTriangle> tris;
      processTriangles(f.scene, f.view, first, std::min(batch, total - first), tris);
      std::vector<std::vector<ScreenTriangle>> out(pes);
      std::vector<char> scratch(pes, 0);
      std::vector<int> owners;
      SortCounters& c = counters[pe.id()];
      for (const ScreenTriangle& tri : tris) {
        ownersOf(grid, pixelBounds(tri), scratch, owners);
        for (int o : owners) out[o].push_back(tri);
        c.trianglesRouted += owners.size();
        if (!owners.empty()) c.trianglesDuplicated += owners.size() - 1;
      }
      for (int o = 0; o < pes; ++o) {
        if (out[o].empty()) continue;
        if (o != pe.id()) c.trianglesSent += out[o].size();
        const size_t bytes = out[o].size() * sizeof(ScreenTriangle);
        triangles.send(pe, o, std::move(out[o]), bytes);
      }
    });

    // Between stages the controlling thread hands each owner its mailbox.
    std::vector<std::vector<ScreenTriangle>> inbox(pes);
    for (int p = 0; p < pes; ++p)
      for (std::vector<ScreenTriangle>& m : triangles.drain(p)) inbox[p].insert(inbox[p].end(), m.begin(), m.end());

    // Stage 2, rasterize and shade: each owner draws its regions from its own triangles.
    std::vector<std::vector<RegionFramebuffer>> drawn(pes);
    std::vector<int> self(pes);
    for (int p = 0; p < pes; ++p) self[p] = p;
    auto owned = makeOwnerScheduler(self);
    rt.runStage("sort-middle rasterize", par::TaskSet::uniform(pes), *owned, [&](par::Pe& pe, par::TaskId) {
      drawn[pe.id()] = drawOwnedRegions(ctx, inbox[pe.id()], grid, pe.id());
    });

    for (const auto& regions : drawn)
      for (const RegionFramebuffer& fb : regions) resolveInto(fb, image);
    SortCounters sum;
    for (const SortCounters& c : counters) sum += c;
    return sum;
  }

 private:
  // Dynamic regions: each PE bins its screen triangles per tile and keeps them; tiles are then
  // handed out on demand and the PE taking a tile pulls that tile's bins from every PE.
  SortCounters renderDynamic(const FrameInputs& f, par::Runtime& rt, const RegionGrid& grid,
                             const ShadingContext& ctx, RegionFramebuffer& image) {
    const int pes = rt.pes();
    const int tiles = grid.regionCount();
    std::vector<SortCounters> counters(pes);
    std::vector<std::vector<std::vector<ScreenTriangle>>> bins(pes, std::vector<std::vector<ScreenTriangle>>(tiles));

    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const uint32_t batch = f.options.batchSize;
    const size_t batches = (total + batch - 1) / batch;
    rt.runStage("sort-middle geometry", par::TaskSet::uniform(batches), [&](par::Pe& pe, par::TaskId t) {
      const uint32_t first = static_cast<uint32_t>(t) * batch;
      std::vector<ScreenTriangle> tris;
      processTriangles(f.scene, f.view, first, std::min(batch, total - first), tris);
      SortCounters& c = counters[pe.id()];
      for (const ScreenTriangle& tri : tris) {
        uint64_t n = 0;
        grid.forEachOverlapped(pixelBounds(tri), [&](int r) {
          bins[pe.id()][r].push_back(tri);
          ++n;
        });
        c.trianglesRouted += n;
        if (n > 0) c.trianglesDuplicated += n - 1;
      }
    });

    std::vector<RegionFramebuffer> drawn(tiles);
    {
      TilePull<ScreenTriangle> pull(rt, "sort-middle tile", bins);
      const par::TaskSet set = grid.regionTasks();
      rt.runStage("sort-middle rasterize", set, [&](par::Pe& pe, par::TaskId t) {
        const std::vector<ScreenTriangle> tris = pull.gather(pe, static_cast<int>(t));
        RegionFramebuffer fb(grid.region(static_cast<int>(t)));
        rasterizeTriangles(tris, fb);
        shadeRegion(ctx, tris, fb);
        drawn[t] = std::move(fb);
      });
      for (int p = 0; p < pes; ++p) counters[p].trianglesSent += pull.itemsSent(p);
    }
    for (const RegionFramebuffer& fb : drawn) resolveInto(fb, image);
    SortCounters sum;
    for (const SortCounters& c : counters) sum += c;
    return sum;
  }
};

}  // namespace

std::unique_ptr<SortPoint> makeSortMiddle() { return std::make_unique<SortMiddle>(); }

}  // namespace pr::raster
