// Tangent frames for normal mapping: per-vertex tangents generated where a file gives none
// (angle-weighted per-corner tangents from the UV parameterisation, orthogonalised against the
// vertex normal, with the bitangent's handedness in w, as MikkTSpace computes them for meshes
// whose vertices are not split by it), and the normal a normal-map texel stands for. Used by
// the loader once and by both renderer families per shaded point.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include "common/scene/scene.h"

namespace pr::scene {

// Tangents (xyz unit, w = +-1 handedness: bitangent = w * cross(normal, tangent)) for the
// vertices [firstVertex, firstVertex + out.size()) from the triangles [firstTriangle, end).
// A vertex without a usable UV parameterisation gets any unit tangent orthogonal to its normal.
void generateTangents(const Scene& scene, uint32_t firstVertex, uint32_t firstTriangle, std::span<glm::vec4> out);

// The shading normal of a tangent-space normal-map sample: texel (RGB in [0, 1]) mapped to
// [-1, 1], its x and y scaled by `scale` (glTF normalTexture.scale), in the frame of unit
// normal n and tangent t (w = handedness). Falls back to n when the frame is degenerate.
glm::vec3 perturbNormal(glm::vec3 n, glm::vec4 tangent, glm::vec3 texel, float scale);

// Unit s and t completing unit n to a right-handed orthonormal basis (s, t, n), continuous but
// for n.z = 0 (Duff et al. 2017, "Building an orthonormal basis, revisited"): the frame of
// every local-coordinate computation in both families.
inline void orthonormalBasis(const glm::vec3& n, glm::vec3& s, glm::vec3& t) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  s = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  t = glm::vec3(b, sign + n.y * n.y * a, -n.y);
}

}  // namespace pr::scene
