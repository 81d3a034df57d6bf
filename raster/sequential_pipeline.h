// The sequential raster pipeline: geometry -> (bin to regions) -> rasterize -> shade, into the
// image, on the calling thread. It is the reference the parallel sort-first,
// sort-middle and sort-last pipelines must match bit for bit, and it calls exactly the stage
// functions they call; it has no sort point (nothing is redistributed).
#pragma once

#include <cstdint>
#include <vector>

#include "common/scene/camera.h"
#include "common/scene/scene.h"
#include "raster/framebuffer.h"
#include "raster/region.h"
#include "raster/stages/geometry.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/shade.h"

namespace pr::raster {

struct SequentialOptions {
  // Screen regions drawn one after the other (tiles, strips); empty = the whole screen at once.
  // The image does not depend on the split: that is what the equivalence tests check.
  std::vector<Rect> regions;
  // Triangles per geometry batch (the PDI of the parallel pipelines); no effect on the image.
  uint32_t batchSize = 4096;
  // The RenderPlan's effects shading honours (see SortOptions::effects).
  scene::EffectSet effects = scene::EffectSet::all();
  // --headlight: a scene without lights is lit from the eye instead of by its environment.
  bool headlight = false;
  // Fill the uncovered pixels with the environment (when the scene shows one). Off where the
  // caller fills them itself (renderFrame does for every sort point, sequential-raster's too).
  bool background = true;
};

struct RasterStats {
  GeometryCounters geometry;
  RasterCounters raster;
  ShadeCounters shade;
  uint64_t regionsDrawn = 0;
  uint64_t trianglesBinned = 0;  // screen triangles handed to regions (counted once per region)
  bool usesHeadlight = false;    // the scene has no punctual light (see ShadingContext)
};

// Renders one frame seen through `view` into a full-screen framebuffer.
RegionFramebuffer renderSequential(const scene::Scene& scene, const FrameView& view,
                                   const SequentialOptions& options = {}, RasterStats* stats = nullptr);

// The same into the caller's image (reallocated only when its size differs from the view's).
void renderSequential(const scene::Scene& scene, const FrameView& view, const SequentialOptions& options,
                      RegionFramebuffer& image, RasterStats* stats = nullptr);

// Same, with the frame view of a scene camera (throws pr::InputError for a bad image size).
RegionFramebuffer renderSequential(const scene::Scene& scene, const scene::Camera& camera, int width,
                                   int height, const SequentialOptions& options = {},
                                   RasterStats* stats = nullptr);

}  // namespace pr::raster
