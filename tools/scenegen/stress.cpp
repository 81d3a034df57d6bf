// Scenes that stress the numerics (`parrender generate stress-*`): each isolates one case where
// floating point, sampling or clipping can go wrong. Their documented behaviour is listed in
// scenes/README.md and checked, with every renderer, by tests/tools/stress_scenes_test.cpp.
// Most share one stage: a 4 x 4 floor at y = 0, a back wall at z = -2, a sphere of radius 0.5
// on the floor, a point light over it and a camera at (0, 1.5, 4) looking at the sphere.
#include <numbers>
#include <string>

#include "tools/scenegen/scene_registry.h"

namespace pr::scenegen {
namespace {

constexpr float kFov = 45.0f * std::numbers::pi_v<float> / 180.0f;

MeshData& append(MeshData& to, const MeshData& from) {
  const uint32_t base = uint32_t(to.positions.size());
  to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
  to.normals.insert(to.normals.end(), from.normals.begin(), from.normals.end());
  for (uint32_t i : from.indices) to.indices.push_back(base + i);
  return to;
}

// An axis-aligned box from its centre and half extents, faces outward.
MeshData makeBox(glm::vec3 c, glm::vec3 h) {
  MeshData box;
  const glm::vec3 x(2 * h.x, 0, 0), y(0, 2 * h.y, 0), z(0, 0, 2 * h.z), lo = c - h, hi = c + h;
  append(box, makeQuad(lo, y, x));                           // -z
  append(box, makeQuad({lo.x, lo.y, hi.z}, x, y));           // +z
  append(box, makeQuad(lo, z, y));                           // -x
  append(box, makeQuad({hi.x, lo.y, lo.z}, y, z));           // +x
  append(box, makeQuad(lo, x, z));                           // -y
  append(box, makeQuad({lo.x, hi.y, lo.z}, z, x));           // +y
  return box;
}

MeshData scaled(MeshData mesh, float s) {
  for (glm::vec3& p : mesh.positions) p *= s;
  return mesh;
}

MeshData sphereAt(glm::vec3 centre, float radius, int segments) {
  MeshData m = makeUvSphere(radius, segments, segments / 2);
  for (glm::vec3& p : m.positions) p += centre;
  return m;
}

struct Stage {
  int floor = -1, wall = -1, sphere = -1;
};

// The shared stage in units of `s`; the point light's candela scale with s^2, so that the
// illuminance, and so the image, does not depend on s.
Stage addStage(GltfBuilder& b, int segments, float s = 1.0f, bool light = true) {
  Stage st;
  st.floor = b.addMaterial({.name = "floor", .baseColor = {0.7f, 0.7f, 0.7f, 1.0f}});
  st.wall = b.addMaterial({.name = "wall", .baseColor = {0.3f, 0.5f, 0.8f, 1.0f}});
  st.sphere = b.addMaterial({.name = "sphere", .baseColor = {0.8f, 0.3f, 0.2f, 1.0f}, .roughness = 0.4f});
  b.addMeshNode("floor", b.addMesh("floor", scaled(makeQuad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}), s), st.floor));
  b.addMeshNode("back wall", b.addMesh("back wall", scaled(makeQuad({-2, 0, -2}, {4, 0, 0}, {0, 3, 0}), s), st.wall));
  b.addMeshNode("sphere", b.addMesh("sphere", scaled(sphereAt({0, 0.5f, 0}, 0.5f, segments), s), st.sphere));
  if (light) b.addPointLight("light", glm::vec3(1.0f), 20.0f * s * s, glm::vec3(0.5f, 2.5f, 1.5f) * s);
  b.addPerspectiveCamera("camera", kFov, 4.0f / 3.0f, 0.01f * s, 100.0f * s, glm::vec3(0, 1.5f, 4) * s,
                         glm::vec3(0, 0.5f, 0) * s);
  return st;
}

}  // namespace

void buildStressScaleSmall(GltfBuilder& b, const SceneParams& p) { addStage(b, p.size, 1e-6f); }
void buildStressScaleLarge(GltfBuilder& b, const SceneParams& p) { addStage(b, p.size, 1e6f); }

void buildStressDegenerate(GltfBuilder& b, const SceneParams& p) {
  const Stage st = addStage(b, p.size);
  // A 16 x 16 grid of cells in front of the sphere, each cell's two triangles followed by two
  // degenerate ones: a repeated vertex and three collinear vertices.
  MeshData mesh;
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) {
      MeshData cell = makeQuad({-1.5f + 3.0f * i / 16, 0.01f, 1.5f - 1.0f * j / 16}, {3.0f / 16, 0, 0}, {0, 0, -1.0f / 16});
      const uint32_t base = uint32_t(mesh.positions.size());
      append(mesh, cell);
      const uint32_t a = base, c = base + 2;
      mesh.positions.push_back(0.5f * (mesh.positions[a] + mesh.positions[c]));  // on the diagonal
      mesh.normals.push_back({0, 1, 0});
      const uint32_t mid = uint32_t(mesh.positions.size()) - 1;
      for (uint32_t d : {a, a, c, a, mid, c}) mesh.indices.push_back(d);
    }
  b.addMeshNode("half degenerate grid", b.addMesh("half degenerate grid", mesh, st.wall));
}

void buildStressZFight(GltfBuilder& b, const SceneParams& p) {
  addStage(b, p.size);
  const int red = b.addMaterial({.name = "red", .baseColor = {0.9f, 0.1f, 0.1f, 1.0f}});
  const int green = b.addMaterial({.name = "green", .baseColor = {0.1f, 0.9f, 0.1f, 1.0f}});
  // Two coincident quads in front of the back wall, and one 1e-7 in front of those.
  const MeshData quad = makeQuad({-1.5f, 0.5f, -1.0f}, {3, 0, 0}, {0, 1.5f, 0});
  b.addMeshNode("coincident red", b.addMesh("coincident red", quad, red));
  b.addMeshNode("coincident green", b.addMesh("coincident green", quad, green));
  b.addMeshNode("nearly coincident", b.addMesh("nearly coincident", makeQuad({-0.5f, 1.2f, -1.0f + 1e-7f}, {1, 0, 0}, {0, 0.5f, 0}), green));
}

void buildStressCameraInside(GltfBuilder& b, const SceneParams& p) {
  // A closed, double-sided sphere of radius 3 around the camera, lit from inside.
  const int shell = b.addMaterial({.name = "shell", .baseColor = {0.6f, 0.6f, 0.5f, 1.0f}, .doubleSided = true});
  const int ball = b.addMaterial({.name = "ball", .baseColor = {0.2f, 0.6f, 0.3f, 1.0f}});
  b.addMeshNode("shell", b.addMesh("shell", makeUvSphere(3.0f, p.size, p.size / 2), shell));
  b.addMeshNode("ball", b.addMesh("ball", sphereAt({0, -0.5f, -1.5f}, 0.5f, p.size), ball));
  b.addPointLight("light", glm::vec3(1.0f), 10.0f, {0.5f, 1.0f, 0.5f});
  b.addPerspectiveCamera("camera", kFov, 4.0f / 3.0f, 0.01f, 100.0f, {0, 0, 1}, {0, -0.5f, -1.5f});
}

void buildStressLightInside(GltfBuilder& b, const SceneParams& p) {
  const Stage st = addStage(b, p.size, 1.0f, /*light=*/false);
  // The only light sits inside a closed box on the floor: none of its light gets out.
  b.addMeshNode("closed box", b.addMesh("closed box", makeBox({1.2f, 0.4f, 0.5f}, {0.4f, 0.4f, 0.4f}), st.wall));
  b.addPointLight("light in the box", glm::vec3(1.0f), 50.0f, {1.2f, 0.4f, 0.5f});
}

void buildStressLightOnSurface(GltfBuilder& b, const SceneParams& p) {
  addStage(b, p.size, 1.0f, /*light=*/false);
  b.addPointLight("light on the floor", glm::vec3(1.0f), 20.0f, {0.9f, 0.0f, 0.6f});
}

void buildStressThinGlass(GltfBuilder& b, const SceneParams& p) {
  addStage(b, p.size);
  // A slab 0.1 thick whose glass absorbs over 1e-3: transmittance colour^(0.1 / 1e-3) =
  // (0.5, 0.8, 0.9)^100, about (8e-31, 2e-10, 3e-5): red below float's normal range.
  const int glass = b.addMaterial({.name = "absorbing glass", .baseColor = glm::vec4(1.0f), .roughness = 0.0f,
                                   .transmission = 1.0f, .ior = 1.5f, .attenuationDistance = 1e-3f,
                                   .attenuationColor = {0.5f, 0.8f, 0.9f}, .thickness = 0.1f});
  b.addMeshNode("slab", b.addMesh("slab", makeBox({-0.9f, 0.6f, 0.8f}, {0.5f, 0.6f, 0.05f}), glass));
}

void buildStressDielectrics(GltfBuilder& b, const SceneParams& p) {
  addStage(b, p.size);
  const int glass = b.addMaterial({.name = "glass", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 1.5f});
  const int water = b.addMaterial({.name = "water", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 1.33f});
  const int flint = b.addMaterial({.name = "flint", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 1.7f});
  // Nested: a water sphere inside a glass sphere. Touching: two glass cubes sharing a face.
  b.addMeshNode("outer glass", b.addMesh("outer glass", sphereAt({-1.1f, 0.6f, 0.6f}, 0.6f, p.size), glass));
  b.addMeshNode("inner water", b.addMesh("inner water", sphereAt({-1.1f, 0.6f, 0.6f}, 0.3f, p.size), water));
  b.addMeshNode("cube a", b.addMesh("cube a", makeBox({0.9f, 0.3f, 0.8f}, {0.3f, 0.3f, 0.3f}), glass));
  b.addMeshNode("cube b", b.addMesh("cube b", makeBox({1.5f, 0.3f, 0.8f}, {0.3f, 0.3f, 0.3f}), flint));
}

void buildStressFireflies(GltfBuilder& b, const SceneParams& p) {
  addStage(b, p.size, 1.0f, /*light=*/false);
  // The only light: a 1 cm square of radiance 1e6 under the ceiling line.
  const int lamp = b.addMaterial({.name = "tiny lamp", .baseColor = {0, 0, 0, 1}, .emissive = glm::vec3(1.0f),
                                  .emissiveStrength = 1e6f});
  b.addMeshNode("tiny lamp", b.addMesh("tiny lamp", makeQuad({0.5f, 2.5f, 0.5f}, {0, 0, -0.01f}, {0.01f, 0, 0}), lamp));
}

void buildStressHugeTriangle(GltfBuilder& b, const SceneParams& p) {
  const int ground = b.addMaterial({.name = "ground", .baseColor = {0.6f, 0.6f, 0.6f, 1.0f}});
  const int ball = b.addMaterial({.name = "ball", .baseColor = {0.8f, 0.3f, 0.2f, 1.0f}});
  // One triangle 2e5 across seen from 1 unit up: about 1e7 pixels wide at 640 x 480.
  MeshData tri;
  tri.positions = {{-1e5f, 0, 1e5f}, {1e5f, 0, 1e5f}, {0, 0, -1e5f}};
  tri.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  tri.indices = {0, 1, 2};
  b.addMeshNode("huge triangle", b.addMesh("huge triangle", tri, ground));
  b.addMeshNode("ball", b.addMesh("ball", sphereAt({0, 0.5f, -2}, 0.5f, p.size), ball));
  b.addPointLight("light", glm::vec3(1.0f), 20.0f, {1, 3, 0});
  b.addPerspectiveCamera("camera", kFov, 4.0f / 3.0f, 0.01f, 1e6f, {0, 1, 1}, {0, 0.5f, -2});
}

void buildStressTotalReflection(GltfBuilder& b, const SceneParams& p) {
  addStage(b, p.size);
  // The camera inside a diamond-like cube (ior 2.4, critical angle 24.6 degrees): most paths
  // reflect totally, again and again, until the depth limit.
  const int diamond = b.addMaterial({.name = "diamond", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 2.4f});
  b.addMeshNode("diamond cube", b.addMesh("diamond cube", makeBox({0, 1.5f, 4.0f}, {0.6f, 0.6f, 0.6f}), diamond));
}

}  // namespace pr::scenegen
