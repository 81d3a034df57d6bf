// Procedural meshes for the bundled scenes (see mesh_gen.h). Runs once per `generate`; the
// arithmetic is plain float so the same arguments give the same bytes.
#include "tools/scenegen/mesh_gen.h"

#include <cmath>
#include <numbers>

#include "common/util/error.h"

namespace pr::scenegen {

MeshData makeQuad(glm::vec3 corner, glm::vec3 u, glm::vec3 v) {
  MeshData mesh;
  glm::vec3 n = glm::normalize(glm::cross(u, v));
  mesh.positions = {corner, corner + u, corner + u + v, corner + v};
  mesh.normals.assign(4, n);
  mesh.indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

MeshData makeBox(glm::vec3 size) {
  const glm::vec3 x(size.x, 0, 0), y(0, size.y, 0), z(0, 0, size.z);
  const glm::vec3 lo(-0.5f * size.x, 0.0f, -0.5f * size.z);
  const glm::vec3 hi = lo + x + y + z;
  // Each face as makeQuad builds it (facing cross(u, v)), outward.
  const MeshData faces[] = {makeQuad(lo, x, z), makeQuad(lo + y, z, x), makeQuad(lo, y, x),
                            makeQuad(hi, -x, -y), makeQuad(lo, z, y),    makeQuad(hi, -y, -z)};
  MeshData box;
  for (const MeshData& f : faces) {
    const uint32_t base = uint32_t(box.positions.size());
    box.positions.insert(box.positions.end(), f.positions.begin(), f.positions.end());
    box.normals.insert(box.normals.end(), f.normals.begin(), f.normals.end());
    for (uint32_t i : f.indices) box.indices.push_back(base + i);
  }
  return box;
}

MeshData makeEllipsoid(glm::vec3 center, glm::vec3 radii, int segments, int rings) {
  PR_CHECK(segments >= 3 && rings >= 2, "sphere needs at least 3 segments and 2 rings");
  MeshData mesh;
  const float pi = std::numbers::pi_v<float>;
  // Vertex grid (rings + 1) x (segments + 1): the seam column is duplicated so a UV set could
  // be added later without re-indexing; each pole row holds coincident copies.
  for (int r = 0; r <= rings; ++r) {
    const float theta = pi * static_cast<float>(r) / static_cast<float>(rings);  // from +y down
    const float sinT = std::sin(theta), cosT = std::cos(theta);
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2.0f * pi * static_cast<float>(s) / static_cast<float>(segments);
      // Unit sphere point; phi runs clockwise seen from +y so the triangles below are CCW
      // seen from outside.
      glm::vec3 p(sinT * std::cos(phi), cosT, -sinT * std::sin(phi));
      if (r == 0 || r == rings) p = glm::vec3(0.0f, cosT, 0.0f);
      mesh.positions.push_back(center + p * radii);
      mesh.normals.push_back(glm::normalize(p / radii));
    }
  }
  const uint32_t row = static_cast<uint32_t>(segments) + 1;
  for (uint32_t r = 0; r < static_cast<uint32_t>(rings); ++r) {
    for (uint32_t s = 0; s < static_cast<uint32_t>(segments); ++s) {
      const uint32_t a = r * row + s, b = a + 1, c = a + row, d = c + 1;  // a b above, c d below
      if (r != 0) mesh.indices.insert(mesh.indices.end(), {a, c, b});  // skip degenerate at the top pole
      if (r + 1 != static_cast<uint32_t>(rings)) mesh.indices.insert(mesh.indices.end(), {b, c, d});
    }
  }
  return mesh;
}

MeshData makeUvSphere(float radius, int segments, int rings) {
  return makeEllipsoid(glm::vec3(0.0f), glm::vec3(radius), segments, rings);
}

MeshData makeHeightField(int cells, float x0, float z0, float extent, const std::function<float(float, float)>& height) {
  PR_CHECK(cells >= 1, "height field needs at least one cell");
  MeshData mesh;
  const int n = cells + 1;
  const float step = extent / static_cast<float>(cells);
  std::vector<float> h(static_cast<size_t>(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) h[static_cast<size_t>(j) * n + i] = height(x0 + i * step, z0 + j * step);
  auto at = [&](int i, int j) { return h[static_cast<size_t>(j) * n + i]; };

  mesh.positions.reserve(h.size());
  mesh.normals.reserve(h.size());
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.positions.emplace_back(x0 + i * step, at(i, j), z0 + j * step);
      const int il = i > 0 ? i - 1 : i, ir = i < cells ? i + 1 : i;
      const int jl = j > 0 ? j - 1 : j, jr = j < cells ? j + 1 : j;
      const float dhdx = (at(ir, j) - at(il, j)) / (static_cast<float>(ir - il) * step);
      const float dhdz = (at(i, jr) - at(i, jl)) / (static_cast<float>(jr - jl) * step);
      // Normal of the surface y = h(x, z): (-dh/dx, 1, -dh/dz), normalised.
      mesh.normals.push_back(glm::normalize(glm::vec3(-dhdx, 1.0f, -dhdz)));
    }
  }
  mesh.indices.reserve(static_cast<size_t>(cells) * cells * 6);
  for (uint32_t j = 0; j < static_cast<uint32_t>(cells); ++j) {
    for (uint32_t i = 0; i < static_cast<uint32_t>(cells); ++i) {
      const uint32_t a = j * n + i, b = a + 1, c = a + n, d = c + 1;  // b is +x, c is +z
      // Seen from +y with x right and z down the page, a -> c -> b turns counter-clockwise.
      mesh.indices.insert(mesh.indices.end(), {a, c, b, b, c, d});
    }
  }
  return mesh;
}

}  // namespace pr::scenegen
