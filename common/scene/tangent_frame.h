// Tangent frames for normal mapping: per-vertex tangents generated where a file gives none
// (angle-weighted per-corner tangents from the UV parameterisation, orthogonalised against the
// vertex normal, with the bitangent's handedness in w, as MikkTSpace computes them for meshes
// whose vertices are not split by it), and the normal a normal-map texel stands for. Used by
// the loader once and by both renderer families per shaded point.
#pragma once

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

}  // namespace pr::scene
