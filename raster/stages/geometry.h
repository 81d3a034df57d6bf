// Geometry stage, the first stage of every raster pipeline (sort-first owners, sort-middle and
// sort-last PEs all call processTriangles on their batch): world-space scene triangles ->
// clip space (model-view-projection of the scene camera) -> near-plane clipping in homogeneous
// space, with guard-band planes far outside the screen -> back-face culling that honours
// double-sided materials -> ScreenTriangles in 24.8 fixed point, ready for setup.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/camera.h"
#include "common/scene/scene.h"

namespace pr::raster {

// Sub-pixel precision of snapped vertex positions: 8 bits, 1/256 pixel.
inline constexpr int kSubpixelBits = 8;
inline constexpr int32_t kSubpixelScale = 1 << kSubpixelBits;

// Largest image side. With the guard band below, snapped coordinates stay within
// +-(2^18 + 2^16) px = +-2^26.4 fixed-point units and edge-function coefficients (coordinate
// differences) within 2^27.4, so every product and sum of setup.h stays below 2^56: exact in
// int64 with bits to spare.
inline constexpr int kMaxImageSidePx = 1 << 16;

// Guard band: a triangle is clipped against the side planes only where it reaches farther
// than 2^18 px from the screen centre, so in practice only the near plane ever clips.
inline constexpr double kGuardBandPx = double(1 << 18);

// A triangle clipped by the near plane and four guard planes has at most 3 + 5 vertices and
// becomes a fan of at most 6 sub-triangles (3 bits of the depth key, depth_resolve.h).
inline constexpr int kMaxPolygonVertices = 8;
inline constexpr int kMaxSubTriangles = kMaxPolygonVertices - 2;

// What the geometry stage needs from the camera for one frame.
struct FrameView {
  int width = 0;
  int height = 0;
  glm::mat4 viewProjection{1.0f};
  glm::vec4 viewDepthRow{0.0f, 0.0f, -1.0f, 0.0f};  // dot(row, (p, 1)) = distance in front of the camera
  float znear = 0.01f;
  bool perspective = true;
  glm::vec3 eye{0.0f};                    // camera position (view vectors for shading)
  glm::vec3 forward{0.0f, 0.0f, -1.0f};   // viewing direction (orthographic view vector)
  float guardX = 1.0f, guardY = 1.0f;     // guard band half extents in NDC
};

// The frame view of a scene camera for a width x height image (the image aspect wins).
// Throws pr::InputError when the size is outside [1, kMaxImageSidePx].
FrameView makeFrameView(const scene::Camera& camera, int width, int height);

// One screen-space triangle (or one piece of a clipped one), the PDI that sort-middle sends to
// region owners. Positions are snapped; the rest is what rasterization and shading interpolate.
struct ScreenTriangle {
  int32_t x[3], y[3];  // 24.8 fixed point, pixel (i, j) has its sample at (i + 0.5, j + 0.5)
  // Depth key, affine in screen space and smaller = nearer: -1/w (perspective, i.e. minus the
  // reciprocal distance along the view axis) or the view-axis distance (orthographic).
  float depth[3];
  float invW[3];        // 1/w, for perspective-correct interpolation
  glm::vec2 bary[3];    // the vertex in barycentrics (b1, b2) of the scene triangle
  uint32_t primitive;   // scene triangle index: the primitive order that breaks depth ties
  uint8_t sub;          // fan index when clipping split the triangle, else 0
  uint8_t backFacing;   // 1: a double-sided triangle seen from behind (shading flips the normal)
};
// The size of one sort-middle message payload per triangle.
static_assert(sizeof(ScreenTriangle) == 80, "ScreenTriangle layout changed: update message accounting");

// Per-batch counts of the geometry stage (Geometry/...).
struct GeometryCounters {
  uint64_t trianglesIn = 0;
  uint64_t culledOutside = 0;     // entirely outside one frustum plane
  uint64_t culledBackFace = 0;
  uint64_t culledDegenerate = 0;  // zero area once snapped
  uint64_t clipped = 0;           // needed near-plane or guard-band clipping
  uint64_t screenTrianglesOut = 0;

  GeometryCounters& operator+=(const GeometryCounters& o);
};

// Geometry for scene triangle `index`: writes 0..kMaxSubTriangles screen triangles to out and
// returns how many. Pure function of (scene, view, index): the same on every PE.
int processTriangle(const scene::Scene& scene, const FrameView& view, uint32_t index,
                    ScreenTriangle* out, GeometryCounters* counters = nullptr);

// Throws pr::InputError "<where>: N triangles exceed the limit of ..." when a scene has more
// triangles than the depth key can order (kMaxPrimitives, 29-bit primitive ids): called where
// a raster render starts, with the scene's triangle count.
void checkRasterLimits(std::string_view where, size_t triangles);

// Geometry for the batch of scene triangles [first, first + count), appended to out in
// primitive order. Called by the PE that owns the batch; touches only out and counters.
void processTriangles(const scene::Scene& scene, const FrameView& view, uint32_t first,
                      uint32_t count, std::vector<ScreenTriangle>& out,
                      GeometryCounters* counters = nullptr);

}  // namespace pr::raster
