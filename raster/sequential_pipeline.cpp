// The sequential raster pipeline: the shared stages chained on one thread. Geometry runs in
// batches in primitive order; each region then gets the screen triangles whose bounds overlap
// it (binning), rasterizes and shades them in its own RegionFramebuffer and is depth-resolved
// into the full-screen image.
#include "raster/sequential_pipeline.h"

#include <algorithm>

#include "common/util/error.h"
#include "raster/stages/depth_resolve.h"
#include "raster/stages/setup.h"

namespace pr::raster {

RegionFramebuffer renderSequential(const scene::Scene& scene, const FrameView& view,
                                   const SequentialOptions& options, RasterStats* stats) {
  PR_CHECK(options.batchSize > 0, "renderSequential: zero batch size");
  RasterStats local;
  RasterStats& st = stats ? *stats : local;
  const Rect screen{0, 0, view.width, view.height};

  std::vector<ScreenTriangle> tris;
  tris.reserve(scene.triangles.size());
  const uint32_t total = static_cast<uint32_t>(scene.triangles.size());
  for (uint32_t first = 0; first < total; first += options.batchSize) {
    processTriangles(scene, view, first, std::min(options.batchSize, total - first), tris, &st.geometry);
  }

  const ShadingContext ctx = makeShadingContext(scene, view);
  st.usesHeadlight = ctx.usesHeadlight;
  RegionFramebuffer image(screen);
  if (options.regions.empty()) {
    rasterizeTriangles(tris, image, &st.raster);
    shadeRegion(ctx, tris, image, &st.shade);
    st.regionsDrawn += 1;
    st.trianglesBinned += tris.size();
    return image;
  }

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
    RegionFramebuffer fb(r);
    rasterizeTriangles(bin, fb, &st.raster);
    shadeRegion(ctx, bin, fb, &st.shade);
    resolveInto(fb, image);
    st.regionsDrawn += 1;
    st.trianglesBinned += bin.size();
  }
  return image;
}

RegionFramebuffer renderSequential(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                   const SequentialOptions& options, RasterStats* stats) {
  return renderSequential(scene, makeFrameView(camera, width, height), options, stats);
}

}  // namespace pr::raster
