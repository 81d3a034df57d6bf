// Sort-last: the sort sits after rasterization. Each PE renders its own primitives (geometry
// batches under the runtime's schedule) over the whole screen into its own full-screen colour
// and depth buffers, shades them, and the Compositor (direct-send or binary-swap, full frame
// or sparse) redistributes pixels by screen region and keeps the nearest fragment per pixel;
// each PE then delivers its composited rectangle to the assembler (frame_assembly.h). The scene
// is replicated (world model: any PE may take any geometry batch).
#include <algorithm>

#include "raster/composite/compositor.h"
#include "raster/frame_assembly.h"
#include "raster/scene_distribution.h"
#include "raster/sort/sort_point.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/shade.h"

namespace pr::raster {
namespace {

class SortLast : public SortPoint {
 public:
  std::string_view name() const override { return "sort-last"; }
  std::vector<ShadeCounters> takeShadeCounters() override { return std::exchange(shade_, {}); }

  void renderFrame(const FrameInputs& f, par::Runtime& rt, RegionFramebuffer& image) override {
    const int pes = rt.pes();
    // The compositor is chosen (and a bad name rejected) before any work is done.
    std::unique_ptr<Compositor> compositor = makeCompositor(f.options.compositor);
    const Rect screen{0, 0, f.view.width, f.view.height};
    const ShadingContext ctx = makeShadingContext(f.scene, f.view, f.options.effects, f.options.headlight);
    declareSortCounters(name(), rt);
    if (distribution_.firstFrame(f.scene, rt)) distributeReplicated(rt, f.scene);

    // Every PE clears its own full-screen buffer (kept from frame to frame).
    buffers_.resize(pes);
    rt.runOnEachPe("sort-last clear", [&](par::Pe& pe) {
      RegionFramebuffer& mine = buffers_[pe.id()];
      if (mine.rect() == screen) mine.clear();
      else mine = RegionFramebuffer(screen);
    });
    std::vector<RegionFramebuffer>& buffers = buffers_;

    // Stage 1, geometry and rasterization of a PE's batches into its own full-screen buffer;
    // the triangle list stays with the PE for deferred shading (triangle index = list position).
    std::vector<std::vector<ScreenTriangle>> tris(pes);
    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const uint32_t batch = f.options.batchSize;
    const size_t batches = (total + batch - 1) / batch;
    rt.runStage("sort-last render", par::TaskSet::uniform(batches), [&](par::Pe& pe, par::TaskId t) {
      std::vector<ScreenTriangle>& mine = tris[pe.id()];
      const size_t before = mine.size();
      const uint32_t first = static_cast<uint32_t>(t) * batch;
      processTriangles(f.scene, f.view, first, std::min(batch, total - first), mine);
      for (size_t i = before; i < mine.size(); ++i)
        rasterizeTriangle(mine[i], static_cast<uint32_t>(i), buffers[pe.id()].window(), nullptr,
                          ctx.alphaTested ? &f.scene : nullptr);
    });

    // Stage 2, shading of each PE's visible pixels, in its own buffer.
    shade_.assign(size_t(pes), ShadeCounters{});
    rt.runOnEachPe("sort-last shade", [&](par::Pe& pe) {
      shadeRegion(ctx, tris[pe.id()], buffers[pe.id()], &shade_[size_t(pe.id())]);
    });

    // Stage 3, the sort: depth compositing by screen region (its counters go to the record).
    const std::vector<Rect> regions = compositor->composite(rt, buffers, f.options.sparse);
    // Each PE delivers the rectangle it composited to the assembler (in place on PE 0).
    FrameAssembly frame(rt, image, pool_);
    rt.runOnEachPe("sort-last assemble", [&](par::Pe& pe) {
      frame.deliver(pe, buffers[pe.id()], regions[pe.id()]);
    });
  }

 private:
  std::vector<RegionFramebuffer> buffers_;  // per PE, full screen, kept between frames
  std::vector<ShadeCounters> shade_;        // per PE, the last frame's
  RegionBufferPool pool_;                   // region message storage, kept between frames
  SceneDistribution distribution_;
};

}  // namespace

std::unique_ptr<SortPoint> makeSortLast() { return std::make_unique<SortLast>(); }

}  // namespace pr::raster
