// The background stage, after every pipeline's last stage: pixels no triangle covers show the
// environment seen through them, as a ray tracer's camera ray that leaves the scene does - so
// both families draw the same picture of a scene lit by an environment. Without an
// environment (or under the headlight) they stay black.
#pragma once

#include "common/scene/scene.h"
#include "raster/framebuffer.h"
#include "raster/stages/geometry.h"

namespace pr::raster {

// Whether the rasterizer lights and backs this scene with its environment (not the headlight).
bool showsEnvironment(const scene::Scene& scene, bool headlight);

// Writes the environment's radiance along each uncovered pixel's view ray (through the pixel
// centre) into fb. Depends only on the view and the pixel, so every sort point and P agree.
void fillBackground(const FrameView& view, const scene::Environment& environment, RegionFramebuffer& fb);

}  // namespace pr::raster
