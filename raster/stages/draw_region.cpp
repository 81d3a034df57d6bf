// Region back end: clear, rasterize, shade (draw_region.h).
#include "raster/stages/draw_region.h"

namespace pr::raster {

void drawRegion(const ShadingContext& ctx, std::span<const ScreenTriangle> tris, const PixelWindow& pixels,
                RasterCounters* raster, ShadeCounters* shade) {
  pixels.clear();
  rasterizeTriangles(tris, pixels, raster, ctx.alphaTested ? ctx.scene : nullptr);
  shadeRegion(ctx, tris, pixels, shade);
}

}  // namespace pr::raster
