// The back end every raster pipeline runs on one screen region of the frame, after its sort
// point (if any): clear the region, rasterize the triangles that overlap it, shade what is
// visible (deferred). Sort-first and sort-middle owners call it per region, the sequential
// pipeline on the whole screen or region by region; sort-last PEs call the same rasterize and
// shade stages over the whole screen.
#pragma once

#include <span>

#include "raster/framebuffer.h"
#include "raster/stages/geometry.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/shade.h"

namespace pr::raster {

// Writes every pixel of the window and nothing else.
void drawRegion(const ShadingContext& ctx, std::span<const ScreenTriangle> tris, const PixelWindow& pixels,
                RasterCounters* raster = nullptr, ShadeCounters* shade = nullptr);

}  // namespace pr::raster
