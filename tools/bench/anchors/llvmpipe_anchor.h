// The rasterization anchor: the same Scene drawn by Mesa's llvmpipe (a sort-middle software
// rasterizer; shared/ANCHORS.md) through OpenGL ES 3 into an offscreen FBO, timed per frame.
// Raster benchmarks in tools/bench/ call it in the same run and print parrender / llvmpipe
// ratios; the readback lets them check both drew the same pixels (coverage mask).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/scene/camera.h"
#include "common/scene/scene.h"

namespace pr::bench {

struct RasterAnchorResult {
  double msPerFrameMedian = 0.0;
  std::vector<double> frameMs;   // each timed frame: glClear + draws + glFinish, wall clock
  // CPU time of the whole process per frame (front end and tile threads together): on a
  // machine shared with other jobs it does not count the time they held the cores.
  double cpuMsPerFrameMedian = 0.0;
  std::vector<double> frameCpuMs;
  double uploadMs = 0.0;         // VBO/IBO upload and shader build, once, not in frameMs
  int coveredPixels = 0;         // pixels some triangle wrote in the final frame
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;     // final frame, RGBA8, row 0 = top (like pr::image::Image)
  std::vector<uint8_t> coverage; // width * height, 1 where a triangle was drawn, row 0 = top
  std::string renderer;          // GL_RENDERER, contains "llvmpipe"
  int threads = 0;               // LP_NUM_THREADS the context was created with
  size_t trianglesDrawn = 0;     // triangles submitted per frame
};

// Draws `scene` seen by `camera` at width x height, `frames` times after one untimed warm-up
// frame (shader compilation happens at the first draw), and reads the last frame back.
// Shading, per pixel: Lambert with the material's base colour factor (times COLOR_0 when
// present) under the scene's first two point/spot/directional lights (E = I / d^2), or the
// raster headlight (L = V, pi lux) when it has none, plus emission; no textures. Back faces of
// single-sided materials are culled, as parrender's geometry stage does. Depth 24-bit.
// threads is LP_NUM_THREADS: 0 = tile work on the calling thread, n = n tile threads besides it.
// A process uses one threads value for its life (see EglContext); another value throws
// std::logic_error. No usable llvmpipe throws AnchorUnavailable; width/height outside
// [1, 16384] or frames < 1 throw std::invalid_argument.
RasterAnchorResult renderWithLlvmpipe(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                      int threads, int frames);

}  // namespace pr::bench
