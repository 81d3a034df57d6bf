// The parallel raster pipelines' entry point: renders frames of a scene with one SortPoint on
// a par::Runtime, for the render command and the tests. A camera orbit (--frames N --orbit)
// renders N frames with the camera circling the scene centre, reusing the sort point between
// frames (sort-first's frame coherence). Every figure of a frame is in runtime.record() (the
// Channels' traffic, and the sort point's per-PE counters by name: Sort/..., Scene/...).
#pragma once

#include <string_view>

#include "common/parallel/runtime.h"
#include "common/scene/camera.h"
#include "common/scene/scene.h"
#include "raster/framebuffer.h"
#include "raster/sort/sort_point.h"

namespace pr::raster {

// One frame with the named sort point (pr::InputError for an unknown name).
RegionFramebuffer renderParallel(const scene::Scene& scene, const FrameView& view, std::string_view method,
                                 const SortOptions& options, par::Runtime& runtime);

// One frame with a sort point kept by the caller across frames.
RegionFramebuffer renderFrame(SortPoint& sortPoint, const scene::Scene& scene, const FrameView& view,
                              const SortOptions& options, par::Runtime& runtime);

// The same into the caller's image (reallocated only when its size differs from the view's):
// an animation keeps one image, as a display keeps its frame buffer.
void renderFrame(SortPoint& sortPoint, const scene::Scene& scene, const FrameView& view, const SortOptions& options,
                 par::Runtime& runtime, RegionFramebuffer& image);

// The camera turned by angleRadians about the vertical (+y) axis through centre: frame i of an
// N-frame orbit uses angle 2 pi i / N.
scene::Camera orbitCamera(const scene::Camera& camera, glm::vec3 centre, float angleRadians);

}  // namespace pr::raster
