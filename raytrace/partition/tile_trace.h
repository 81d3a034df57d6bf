// An image-space tile as every world-model tracer renders it (image_space.cpp, the farm's
// servers): the area cut into square tiles, and one tile's camera rays traced to completion
// into a film of its own, which then travels as a FilmBlock.
#pragma once

#include <algorithm>
#include <vector>

#include "raytrace/core/bvh.h"
#include "raytrace/integrators/film.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/integrators/trace_stats.h"

namespace pr::rt {

// area cut into tiles of w x h pixels, row by row (the last row and column narrower).
inline std::vector<PixelRect> tilesOf(const PixelRect& area, int w, int h) {
  std::vector<PixelRect> tiles;
  for (int y = area.y0; y < area.y1; y += h)
    for (int x = area.x0; x < area.x1; x += w)
      tiles.push_back(PixelRect{x, y, std::min(area.x1, x + w), std::min(area.y1, y + h)});
  return tiles;
}
inline std::vector<PixelRect> tilesOf(const PixelRect& area, int size) { return tilesOf(area, size, size); }

// The tile's samples, traced on PE pe with the whole scene's BVH; its rays added to stats.
inline Film traceTile(const Integrator& integrator, const Bvh& bvh, const PixelRect& rect, int width, int height,
                      int pe, TraceStats& stats) {
  Film tile(rect, width, height, integrator.options().spp);
  std::vector<RayMessage> queue;
  integrator.cameraRays(rect, queue);
  integrator.traceToCompletion(bvh, queue, tile, stats, pe);
  return tile;
}

}  // namespace pr::rt
