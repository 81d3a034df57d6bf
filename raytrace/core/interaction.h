// The surface interaction at a hit: what shading needs from the Scene (position, geometric and
// shading normals, uv, material) and how new rays leave the surface without re-hitting it.
// Made by the PE that owns the hit triangle (the one holding its geometry), after a
// closest-hit query; integrators read it and spawn shadow and bounce rays from it.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"

namespace pr::rt {

struct SurfaceInteraction {
  glm::vec3 position{0.0f};         // from the barycentrics, so its error is a few ulps
  glm::vec3 geometricNormal{0.0f};  // unit, from the winding (counter-clockwise = front)
  glm::vec3 shadingNormal{0.0f};    // unit, interpolated vertex normals, on geometricNormal's side
  glm::vec2 uv{0.0f};               // UV set 0 (zero when the scene has none)
  glm::vec4 colour{1.0f};           // COLOR_0 (1 when the scene has none)
  glm::vec4 tangent{0.0f};          // interpolated tangent (w = handedness), or an anisotropic
                                    // material's dp/du; zero = neither
  glm::vec3 wo{0.0f};               // unit direction back towards the ray origin
  uint32_t material = 0;
  uint32_t triangle = kNoTriangle;
  float t = 0.0f;
  glm::vec3 magnitude{0.0f};  // largest |coordinate| of the triangle's vertices per axis (offset scale)
  bool frontFace = true;   // the ray arrived from the side geometricNormal points to
};

// Reads the hit triangle's vertex data. The hit must come from a query on this scene's
// triangles (PR_CHECK on the index).
SurfaceInteraction makeInteraction(const scene::Scene& scene, const Ray& ray, const Hit& hit);

// Origin for a ray leaving the surface in direction `dir`: offset to the side `dir` points to,
// so reflection and transmission both start on the correct side (ray_offset.h).
glm::vec3 spawnOrigin(const SurfaceInteraction& si, const glm::vec3& dir);

// A ray from the surface in direction `dir`, for t in [0, inf).
Ray spawnRay(const SurfaceInteraction& si, const glm::vec3& dir);

// A shadow ray from the surface to a point off any surface (point or spot light position):
// d = target - origin, t in [0, 1].
Ray spawnRayTo(const SurfaceInteraction& si, const glm::vec3& target);

// A shadow ray between two surfaces (a sampled point on an area light): both ends are offset
// towards each other, so neither surface can occlude the segment; t in [0, 1].
Ray spawnRayTo(const SurfaceInteraction& from, const SurfaceInteraction& to);

}  // namespace pr::rt
