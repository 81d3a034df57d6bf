// Scenes and cameras built in code for the raster tests (no loader involved): triangle soups,
// tessellated planes and cameras whose pixel mapping is known exactly.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/camera.h"
#include "common/scene/scene.h"
#include "raster/region.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/setup.h"

namespace pr::test {

// A scene with one white diffuse material (single-sided) and no vertices yet.
inline scene::Scene emptyScene() {
  scene::Scene s;
  scene::Material m;
  m.name = "white";
  m.metallicFactor = 0.0f;
  m.roughnessFactor = 1.0f;
  s.materials.push_back(m);
  return s;
}

// Appends one triangle with its own three vertices (normals left to the scene: empty normals
// make shading use the geometric normal).
inline uint32_t addTriangle(scene::Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material = 0) {
  uint32_t base = static_cast<uint32_t>(s.positions.size());
  s.positions.insert(s.positions.end(), {a, b, c});
  s.triangles.push_back(scene::Triangle{{base, base + 1, base + 2}, material});
  return static_cast<uint32_t>(s.triangles.size() - 1);
}

// A camera at `eye` looking at `target` with +y up.
inline scene::Camera lookAtCamera(glm::vec3 eye, glm::vec3 target, float yfov = 0.8f, float znear = 0.01f) {
  scene::Camera c;
  glm::vec3 f = glm::normalize(target - eye);
  glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0.0f, 1.0f, 0.0f)));
  glm::vec3 u = glm::cross(r, f);
  c.cameraToWorld = glm::mat4(glm::vec4(r, 0.0f), glm::vec4(u, 0.0f), glm::vec4(-f, 0.0f), glm::vec4(eye, 1.0f));
  c.yfov = yfov;
  c.znear = znear;
  return c;
}

// An orthographic camera at z = 10 looking down -z whose pixel (i, j) of a width x height image
// (powers of two keep the mapping exact) has its sample at world (i + 0.5 - width/2,
// height/2 - j - 0.5): one world unit per pixel.
inline scene::Camera pixelOrthoCamera(int height) {
  scene::Camera c;
  c.projection = scene::Projection::Orthographic;
  c.cameraToWorld = glm::mat4(1.0f);
  c.cameraToWorld[3] = glm::vec4(0.0f, 0.0f, 10.0f, 1.0f);
  c.ymag = float(height) / 2.0f;
  c.xmag = c.ymag;
  c.znear = 0.1f;
  c.zfar = 100.0f;
  return c;
}

// Screen triangle straight from fixed-point positions (bypassing geometry), for rasterizer tests.
inline raster::ScreenTriangle fixedTriangle(glm::ivec2 a, glm::ivec2 b, glm::ivec2 c, uint32_t primitive = 0) {
  raster::ScreenTriangle t{};
  glm::ivec2 v[3] = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    t.x[k] = v[k].x;
    t.y[k] = v[k].y;
    t.depth[k] = 0.5f;
    t.invW[k] = 1.0f;
  }
  t.bary[1] = glm::vec2(1.0f, 0.0f);
  t.bary[2] = glm::vec2(0.0f, 1.0f);
  t.primitive = primitive;
  return t;
}

// The same with b and c swapped when needed for positive area (the front-facing winding).
inline raster::ScreenTriangle positiveTriangle(glm::ivec2 a, glm::ivec2 b, glm::ivec2 c, uint32_t primitive = 0) {
  int64_t area2 = int64_t(c.y - b.y) * (a.x - b.x) - int64_t(c.x - b.x) * (a.y - b.y);
  return area2 < 0 ? fixedTriangle(a, c, b, primitive) : fixedTriangle(a, b, c, primitive);
}

// How many triangles cover each pixel of a width x height screen (row-major).
inline std::vector<int> coverageCounts(int width, int height, const std::vector<raster::ScreenTriangle>& tris,
                                       const raster::Rect* region = nullptr) {
  std::vector<int> count(static_cast<size_t>(width) * height, 0);
  raster::Rect screen{0, 0, width, height};
  for (const auto& t : tris) {
    raster::TriangleSetup s;
    if (!raster::setupTriangle(t, s)) continue;
    raster::forEachCoveredPixel(s, region ? *region : screen, [&](int x, int y, int64_t, int64_t) {
      ++count[static_cast<size_t>(y) * width + x];
    });
  }
  return count;
}

}  // namespace pr::test
