// Tangent generation and normal-map perturbation (see tangent_frame.h).
#include "common/scene/tangent_frame.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace pr::scene {

namespace {

// A unit vector orthogonal to unit n.
glm::vec3 anyOrthogonal(glm::vec3 n) {
  glm::vec3 s, t;
  orthonormalBasis(n, s, t);
  return s;
}

float cornerAngle(glm::vec3 a, glm::vec3 b) {
  const float la = glm::length(a), lb = glm::length(b);
  if (!(la > 0.0f) || !(lb > 0.0f)) return 0.0f;
  return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f));
}

}  // namespace

void generateTangents(const Scene& scene, uint32_t firstVertex, uint32_t firstTriangle, std::span<glm::vec4> out) {
  std::vector<glm::vec3> tangent(out.size(), glm::vec3(0.0f)), bitangent(out.size(), glm::vec3(0.0f));
  for (size_t t = firstTriangle; t < scene.triangles.size(); ++t) {
    const Triangle& tri = scene.triangles[t];
    const glm::vec3 p[3] = {scene.positions[tri.v[0]], scene.positions[tri.v[1]], scene.positions[tri.v[2]]};
    const glm::vec2 uv[3] = {scene.uvs[tri.v[0]], scene.uvs[tri.v[1]], scene.uvs[tri.v[2]]};
    const glm::vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const glm::vec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (!(std::fabs(det) > 0.0f)) continue;  // no UV parameterisation on this triangle
    // dp/du and dp/dv: the directions of increasing u and v on the surface.
    const glm::vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
    const glm::vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
    if (!std::isfinite(dpdu.x + dpdu.y + dpdu.z + dpdv.x + dpdv.y + dpdv.z)) continue;
    // MikkTSpace weighs each corner by its angle and uses unit-length per-triangle directions.
    const float lu = glm::length(dpdu), lv = glm::length(dpdv);
    if (!(lu > 0.0f) || !(lv > 0.0f)) continue;
    for (int k = 0; k < 3; ++k) {
      const float w = cornerAngle(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
      const size_t i = tri.v[k] - firstVertex;
      tangent[i] += w * dpdu / lu;
      bitangent[i] += w * dpdv / lv;
    }
  }
  for (size_t i = 0; i < out.size(); ++i) {
    const glm::vec3 n = scene.normals[firstVertex + i];
    glm::vec3 t = tangent[i] - glm::dot(tangent[i], n) * n;  // Gram-Schmidt against the normal
    const float len = glm::length(t);
    t = len > 1e-20f && std::isfinite(len) ? t / len : anyOrthogonal(n);
    // Handedness: whether the UV v direction agrees with cross(n, t) (mirrored UVs give -1).
    const float w = glm::dot(glm::cross(n, t), bitangent[i]) < 0.0f ? -1.0f : 1.0f;
    out[i] = glm::vec4(t, w);
  }
}

glm::vec3 perturbNormal(glm::vec3 n, glm::vec4 tangent, glm::vec3 texel, float scale) {
  glm::vec3 t(tangent);
  t -= glm::dot(t, n) * n;
  const float len = glm::length(t);
  if (!(len > 1e-12f) || !std::isfinite(len)) return n;
  t /= len;
  const glm::vec3 b = (tangent.w < 0.0f ? -1.0f : 1.0f) * glm::cross(n, t);
  glm::vec3 m = texel * 2.0f - 1.0f;
  m.x *= scale;
  m.y *= scale;
  const glm::vec3 mapped = m.x * t + m.y * b + m.z * n;
  const float ml = glm::length(mapped);
  return ml > 0.0f && std::isfinite(ml) ? mapped / ml : n;
}

}  // namespace pr::scene
