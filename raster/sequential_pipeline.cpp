// The sequential raster pipeline: the shared stages chained on one thread. Geometry runs in
// batches in primitive order; then the whole screen, or each region in turn with the screen
// triangles whose bounds overlap it (binning), is drawn: cleared, rasterized, shaded.
#include "raster/sequential_pipeline.h"

#include <algorithm>

#include "common/util/error.h"
#include "raster/stages/draw_region.h"
#include "raster/stages/setup.h"
#include "raster/stages/background.h"

namespace pr::raster {

void renderSequential(const scene::Scene& scene, const FrameView& view, const SequentialOptions& options,
                      RegionFramebuffer& image, RasterStats* stats) {
  PR_CHECK(options.batchSize > 0, "renderSequential: zero batch size");
  checkRasterLimits("scene " + scene.source.string(), scene.triangles.size());
  RasterStats local;
  RasterStats& st = stats ? *stats : local;
  const Rect screen{0, 0, view.width, view.height};
  if (!(image.rect() == screen)) image = RegionFramebuffer(screen);

  std::vector<ScreenTriangle> tris;
  tris.reserve(scene.triangles.size());
  const uint32_t total = static_cast<uint32_t>(scene.triangles.size());
  for (uint32_t first = 0; first < total; first += options.batchSize) {
    processTriangles(scene, view, first, std::min(options.batchSize, total - first), tris, &st.geometry);
  }

  const ShadingContext ctx = makeShadingContext(scene, view, options.effects, options.headlight);
  st.usesHeadlight = ctx.usesHeadlight;
  auto draw = [&](std::span<const ScreenTriangle> list, const PixelWindow& pixels) {
    drawRegion(ctx, list, pixels, &st.raster, &st.shade);
    st.regionsDrawn += 1;
    st.trianglesBinned += list.size();
  };
  if (options.regions.empty()) {
    draw(tris, image.window());
    if (options.background && showsEnvironment(scene, options.headlight)) fillBackground(view, *scene.environment, image);
    return;
  }

  // Each region is drawn whole; the pixels no region covers are cleared here.
  image.clear();
  std::vector<Rect> bounds(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) bounds[i] = pixelBounds(tris[i]);
  std::vector<ScreenTriangle> bin;
  for (const Rect& region : options.regions) {
    Rect r = intersect(region, screen);
    if (r.empty()) continue;
    bin.clear();
    for (size_t i = 0; i < tris.size(); ++i) {
      if (overlaps(bounds[i], r)) bin.push_back(tris[i]);
    }
    draw(bin, image.window(r));
  }
  if (options.background && showsEnvironment(scene, options.headlight)) fillBackground(view, *scene.environment, image);
}

RegionFramebuffer renderSequential(const scene::Scene& scene, const FrameView& view,
                                   const SequentialOptions& options, RasterStats* stats) {
  RegionFramebuffer image;
  renderSequential(scene, view, options, image, stats);
  return image;
}

RegionFramebuffer renderSequential(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                   const SequentialOptions& options, RasterStats* stats) {
  return renderSequential(scene, makeFrameView(camera, width, height), options, stats);
}

}  // namespace pr::raster
