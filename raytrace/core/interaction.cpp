// Surface interactions and spawned rays (see interaction.h). Runs on the PE that shades a hit;
// reads the Scene's vertex arrays for the hit triangle only.
#include "raytrace/core/interaction.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/util/error.h"
#include "raytrace/core/ray_offset.h"

namespace pr::rt {
namespace {

// Unit normal of the winding. A sliver can underflow the float cross product (and degenerate
// triangles are never hit), so the double product backs it up; a true zero gives +z.
glm::vec3 windingNormal(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(n);
  if (len > 0.0f && std::isfinite(len)) return n / len;
  const glm::dvec3 nd = glm::cross(glm::dvec3(p1) - glm::dvec3(p0), glm::dvec3(p2) - glm::dvec3(p0));
  const double lend = glm::length(nd);
  return lend > 0.0 ? glm::vec3(nd / lend) : glm::vec3(0.0f, 0.0f, 1.0f);
}

}  // namespace

SurfaceInteraction makeInteraction(const scene::Scene& scene, const Ray& ray, const Hit& hit) {
  PR_CHECK(hit.triangle < scene.triangles.size(), "hit triangle " + std::to_string(hit.triangle) + " not in scene");
  const scene::Triangle& tri = scene.triangles[hit.triangle];
  const glm::vec3 p0 = scene.positions[tri.v[0]], p1 = scene.positions[tri.v[1]], p2 = scene.positions[tri.v[2]];
  const float b0 = 1.0f - hit.u - hit.v, b1 = hit.u, b2 = hit.v;

  SurfaceInteraction si;
  si.position = b0 * p0 + b1 * p1 + b2 * p2;
  si.geometricNormal = windingNormal(p0, p1, p2);
  si.shadingNormal = si.geometricNormal;
  if (scene.normals.size() == scene.positions.size()) {
    const glm::vec3 n = b0 * scene.normals[tri.v[0]] + b1 * scene.normals[tri.v[1]] + b2 * scene.normals[tri.v[2]];
    const float len = glm::length(n);
    // Opposite vertex normals can cancel; then the geometric normal is the only direction left.
    if (len > 0.0f && std::isfinite(len)) {
      si.shadingNormal = n / len;
      // Shading must see the same front as the geometry (inside/outside tests of glass use
      // the winding), so a vertex normal pointing to the back is flipped.
      if (glm::dot(si.shadingNormal, si.geometricNormal) < 0.0f) si.shadingNormal = -si.shadingNormal;
    }
  }
  if (scene.uvs.size() == scene.positions.size())
    si.uv = b0 * scene.uvs[tri.v[0]] + b1 * scene.uvs[tri.v[1]] + b2 * scene.uvs[tri.v[2]];
  if (scene.colors.size() == scene.positions.size())
    si.colour = b0 * scene.colors[tri.v[0]] + b1 * scene.colors[tri.v[1]] + b2 * scene.colors[tri.v[2]];
  if (scene.tangents.size() == scene.positions.size()) {
    const glm::vec4 t0 = scene.tangents[tri.v[0]], t1 = scene.tangents[tri.v[1]], t2 = scene.tangents[tri.v[2]];
    // The handedness is per vertex and the same over a primitive's triangle (MikkTSpace splits
    // vertices where it changes); interpolating it would only blur the sign.
    si.tangent = glm::vec4(glm::vec3(b0 * t0 + b1 * t1 + b2 * t2), t0.w);
  }
  if (si.tangent == glm::vec4(0.0f) && scene.materials[tri.material].anisotropyStrength > 0.0f &&
      scene.uvs.size() == scene.positions.size()) {
    // An anisotropic lobe needs the uv tangent even without a normal map: dp/du of the triangle.
    const glm::vec2 t0 = scene.uvs[tri.v[0]], d1 = scene.uvs[tri.v[1]] - t0, d2 = scene.uvs[tri.v[2]] - t0;
    const float det = d1.x * d2.y - d1.y * d2.x;
    if (std::fabs(det) > 1.0e-12f) {
      const glm::vec3 dpdu = ((p1 - p0) * d2.y - (p2 - p0) * d1.y) / det;
      if (std::isfinite(dpdu.x + dpdu.y + dpdu.z)) si.tangent = glm::vec4(dpdu, 1.0f);
    }
  }
  const float dirLen = glm::length(ray.direction);
  si.wo = dirLen > 0.0f ? -ray.direction / dirLen : glm::vec3(0.0f);
  si.material = tri.material;
  si.triangle = hit.triangle;
  si.t = hit.t;
  si.magnitude = glm::max(glm::abs(p0), glm::max(glm::abs(p1), glm::abs(p2)));
  si.frontFace = glm::dot(si.geometricNormal, ray.direction) < 0.0f;
  return si;
}

glm::vec3 spawnOrigin(const SurfaceInteraction& si, const glm::vec3& dir) {
  const glm::vec3 n = glm::dot(si.geometricNormal, dir) >= 0.0f ? si.geometricNormal : -si.geometricNormal;
  return offsetRayOrigin(si.position, n, si.magnitude);
}

Ray spawnRay(const SurfaceInteraction& si, const glm::vec3& dir) {
  return Ray{spawnOrigin(si, dir), 0.0f, dir, kInfinity};
}

// The ray stops 1e-4 of the way short of a point target: a point light lying exactly on a
// surface (stress-light-on-surface) is not shadowed by the surface it lies on.
Ray spawnRayTo(const SurfaceInteraction& si, const glm::vec3& target) {
  constexpr float kShortOfTarget = 1.0f - 1e-4f;
  const glm::vec3 origin = spawnOrigin(si, target - si.position);
  return Ray{origin, 0.0f, target - origin, kShortOfTarget};
}

Ray spawnRayTo(const SurfaceInteraction& from, const SurfaceInteraction& to) {
  const glm::vec3 origin = spawnOrigin(from, to.position - from.position);
  const glm::vec3 target = spawnOrigin(to, from.position - to.position);
  return Ray{origin, 0.0f, target - origin, 1.0f};
}

}  // namespace pr::rt
