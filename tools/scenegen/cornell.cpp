// The `cornell` and `cornell-diffuse` scenes: the classic Cornell box (dimensions of the
// Cornell measurement, in units of 100 mm) with two spheres under a ceiling area light, the
// test scene of Jensen 1996, figure 6 (glass sphere front right, mirror sphere back left).
// `cornell` is the default scene; `cornell-diffuse` swaps both spheres for white diffuse;
// `cornell-glass` keeps the glass sphere and makes the other white diffuse (the photon map's
// accuracy benchmark: caustics through glass and colour bleeding, no mirror); `cornell-rough`
// has a rough metal block (the Cornell tall block) back left and a frosted, partly
// transmissive sphere front right: glossy light for the photon map's convergence sweep.
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "tools/scenegen/scene_registry.h"

namespace pr::scenegen {
namespace {

// Box: x in [0, W] (left wall red, right wall green), y in [0, H], z in [-D, 0]; the front
// (z = 0) is open and the camera looks in along -z.
constexpr float kWidth = 5.56f, kHeight = 5.488f, kDepth = 5.592f;
constexpr float kSphereRadius = 1.0f;

// What the two objects are (back left, front right): spheres, or the rough metal block and
// the frosted sphere.
enum class Spheres { MirrorAndGlass, Diffuse, DiffuseAndGlass, RoughMetalAndFrosted };

// The two spheres: one tessellation shared by both (instanced by node translation).
void addSpheres(GltfBuilder& b, int segments, Spheres spheres) {
  const MeshData sphere = makeUvSphere(kSphereRadius, segments, segments / 2);
  const int diffuseSphere =
      spheres == Spheres::MirrorAndGlass ? -1
                                         : b.addMaterial({.name = "sphere white", .baseColor = {0.73f, 0.73f, 0.73f, 1.0f}, .specular = 0.0f});
  const int backMaterial =
      spheres == Spheres::MirrorAndGlass
          ? b.addMaterial({.name = "mirror", .baseColor = glm::vec4(1.0f), .metallic = 1.0f, .roughness = 0.0f})
          : diffuseSphere;
  const int frontMaterial =
      spheres == Spheres::Diffuse
          ? diffuseSphere
          : b.addMaterial({.name = "glass", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 1.5f});
  const bool specularBack = spheres == Spheres::MirrorAndGlass, glassFront = spheres != Spheres::Diffuse;
  const int backMesh = b.addMesh(specularBack ? "mirror sphere" : "back sphere", sphere, backMaterial);
  const int frontMesh = frontMaterial == backMaterial ? backMesh
                                                      : b.addMeshSharingGeometry(glassFront ? "glass sphere" : "front sphere",
                                                                                 backMesh, frontMaterial);
  b.addMeshNode(specularBack ? "mirror sphere" : "back sphere", backMesh, {.translation = {1.6f, kSphereRadius, -3.6f}});
  b.addMeshNode(glassFront ? "glass sphere" : "front sphere", frontMesh, {.translation = {3.8f, kSphereRadius, -1.8f}});
}

void buildBox(GltfBuilder& b, const SceneParams& params, Spheres spheres) {
  // Reflectances of the Cornell box paints (about 0.73 white, red and green as measured),
  // purely Lambertian as in Jensen's box: KHR_materials_specular 0, no Fresnel layer.
  const int white = b.addMaterial({.name = "white", .baseColor = {0.73f, 0.73f, 0.73f, 1.0f}, .specular = 0.0f});
  const int red = b.addMaterial({.name = "red", .baseColor = {0.63f, 0.065f, 0.05f, 1.0f}, .specular = 0.0f});
  const int green = b.addMaterial({.name = "green", .baseColor = {0.14f, 0.45f, 0.091f, 1.0f}, .specular = 0.0f});
  // The light: a pure emitter (black base colour). Radiance = emissiveFactor * strength = 30,
  // which puts about 0.3 of diffuse radiance on the floor below it
  // (E = L A / h^2 = 30 * 1.365 / 5.48^2 = 1.36; 0.73 * 1.36 / pi = 0.32).
  const int light = b.addMaterial({.name = "light",
                                   .baseColor = {0.0f, 0.0f, 0.0f, 1.0f},
                                   .emissive = glm::vec3(1.0f),
                                   .emissiveStrength = 30.0f,
                                   .specular = 0.0f});

  // Walls: each quad faces into the box (makeQuad faces cross(u, v)).
  const glm::vec3 x(kWidth, 0, 0), y(0, kHeight, 0), z(0, 0, -kDepth);
  b.addMeshNode("floor", b.addMesh("floor", makeQuad({0, 0, 0}, x, z), white));
  b.addMeshNode("ceiling", b.addMesh("ceiling", makeQuad({0, kHeight, 0}, z, x), white));
  b.addMeshNode("back wall", b.addMesh("back wall", makeQuad({0, 0, -kDepth}, x, y), white));
  b.addMeshNode("left wall", b.addMesh("left wall", makeQuad({0, 0, 0}, z, y), red));
  b.addMeshNode("right wall", b.addMesh("right wall", makeQuad({kWidth, 0, 0}, y, z), green));

  // Light: the Cornell opening (1.30 x 1.05, centred), 5 mm below the ceiling so the two
  // surfaces never share a depth, facing down.
  const glm::vec3 lightCorner(2.13f, kHeight - 0.005f, -2.27f);
  b.addMeshNode("light", b.addMesh("light", makeQuad(lightCorner, {0, 0, -1.05f}, {1.30f, 0, 0}), light));

  const int segments = params.size;
  if (spheres == Spheres::RoughMetalAndFrosted) {
    // The Cornell tall block (1.65 x 3.30 x 1.65, turned 17 degrees) in a brushed-looking
    // metal, and a frosted sphere that lets 0.8 through over a white diffuse base.
    const int metal = b.addMaterial({.name = "rough metal", .baseColor = {0.9f, 0.9f, 0.9f, 1.0f}, .metallic = 1.0f, .roughness = 0.3f});
    const int frosted = b.addMaterial(
        {.name = "frosted glass", .baseColor = {0.9f, 0.9f, 0.9f, 1.0f}, .roughness = 0.3f, .transmission = 0.8f, .ior = 1.5f});
    b.addMeshNode("metal block", b.addMesh("metal block", makeBox({1.65f, 3.30f, 1.65f}), metal),
                  {.translation = {1.85f, 0.0f, -3.8f}, .rotation = glm::angleAxis(glm::radians(17.0f), glm::vec3(0, 1, 0))});
    b.addMeshNode("frosted sphere", b.addMesh("frosted sphere", makeUvSphere(kSphereRadius, segments, segments / 2), frosted),
                  {.translation = {3.8f, kSphereRadius, -1.8f}});
  } else {
    addSpheres(b, segments, spheres);
  }

  // Camera of the Cornell data: 8 units in front of the opening on the box's axis, a 35 mm
  // lens on a 25 mm film: yfov = 2 atan(12.5 / 35) = 39.3 degrees, square image.
  const glm::vec3 eye(kWidth / 2, kHeight / 2, 8.0f);
  b.addPerspectiveCamera("camera", 2.0f * std::atan(12.5f / 35.0f), 1.0f, 0.1f, 100.0f, eye,
                         {kWidth / 2, kHeight / 2, -kDepth / 2});
}

}  // namespace

void buildCornell(GltfBuilder& builder, const SceneParams& params) { buildBox(builder, params, Spheres::MirrorAndGlass); }
void buildCornellDiffuse(GltfBuilder& builder, const SceneParams& params) { buildBox(builder, params, Spheres::Diffuse); }
void buildCornellGlass(GltfBuilder& builder, const SceneParams& params) { buildBox(builder, params, Spheres::DiffuseAndGlass); }
void buildCornellRough(GltfBuilder& builder, const SceneParams& params) {
  buildBox(builder, params, Spheres::RoughMetalAndFrosted);
}

}  // namespace pr::scenegen
