// The raster family's one-PE reference: the sequential pipeline (raster/sequential_pipeline.h)
// run as one stage of one task on one PE, so that its time is measured like every sort
// point's and the speed-ups Ts/Tn of sort-first, sort-middle and sort-last are taken against
// the program with no sort point at all, not against the fastest of them at P = 1. It draws
// the whole screen at once: nothing is redistributed, so nothing is sent.
#include <utility>

#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_point.h"

namespace pr::raster {

namespace {

class SequentialRaster final : public SortPoint {
 public:
  std::string_view name() const override { return "sequential-raster"; }

  std::vector<ShadeCounters> takeShadeCounters() override { return std::exchange(shade_, {}); }

  void renderFrame(const FrameInputs& f, par::Runtime& rt, RegionFramebuffer& image) override {
    SequentialOptions options;
    options.batchSize = f.options.batchSize;
    options.effects = f.options.effects;
    options.headlight = f.options.headlight;
    options.background = false;  // renderFrame fills it after every sort point, this one's too
    shade_.assign(size_t(rt.pes()), ShadeCounters{});
    // PE 0 holds the image: the one-PE stage draws straight into it.
    rt.runOnOnePe("sequential-raster frame", 0, [&](par::Pe& pe) {
      RasterStats stats;
      renderSequential(f.scene, f.view, options, image, &stats);
      shade_[size_t(pe.id())] = stats.shade;
    });
  }

 private:
  std::vector<ShadeCounters> shade_;
};

}  // namespace

std::unique_ptr<SortPoint> makeSequentialRaster() { return std::make_unique<SequentialRaster>(); }

}  // namespace pr::raster
