// Procedural triangle meshes for the bundled scenes: quads (walls, lights), UV spheres and
// ellipsoids with smooth normals, and height-field grids (the landscape terrain). Each is
// indexed, counter-clockwise seen from outside, and goes to GltfBuilder::addMesh.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

namespace pr::scenegen {

struct MeshData {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // unit length, one per position
  std::vector<uint32_t> indices;   // three per triangle
  size_t triangleCount() const { return indices.size() / 3; }
};

// The parallelogram corner, corner+u, corner+u+v, corner+v as two triangles, facing
// normalize(cross(u, v)).
MeshData makeQuad(glm::vec3 corner, glm::vec3 u, glm::vec3 v);

// An axis-aligned box of `size` standing on the origin: x and z centred, y from 0 to size.y.
// Six faces of two triangles each with flat outward normals (4 vertices per face).
MeshData makeBox(glm::vec3 size);

// A UV sphere around the origin: `segments` around the y axis, `rings` from pole to pole
// (>= 3 and >= 2). 2 * segments * (rings - 1) triangles: the pole rows are single triangles.
MeshData makeUvSphere(float radius, int segments, int rings);

// The UV sphere scaled by `radii` per axis, with the ellipsoid's true normals (not the
// scaled sphere's): n ~ (x / a^2, y / b^2, z / c^2).
MeshData makeEllipsoid(glm::vec3 center, glm::vec3 radii, int segments, int rings);

// A cells x cells grid over [x0, x0 + extent] x [z0, z0 + extent] in the xz plane with
// y = height(x, z) at each of the (cells + 1)^2 vertices; 2 * cells^2 triangles facing +y.
// Normals are central differences of the sampled heights (one-sided at the border).
MeshData makeHeightField(int cells, float x0, float z0, float extent, const std::function<float(float, float)>& height);

}  // namespace pr::scenegen
