// Scenes built in code for the integrator tests: a lit ground plane, a closed sphere (white
// furnace, nested glass), a mirror box. Every scene is small so each test stays under a second.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/environment.h"
#include "common/scene/scene.h"

namespace pr::test {

inline uint32_t addMaterial(scene::Scene& s, scene::Material m) {
  s.materials.push_back(std::move(m));
  return uint32_t(s.materials.size() - 1);
}

// A purely Lambertian material of the given albedo: KHR_materials_specular's specularFactor 0
// removes the dielectric Fresnel layer, as the glTF spec spells a diffuse-only surface.
inline scene::Material diffuse(float albedo) {
  scene::Material m;
  m.baseColorFactor = glm::vec4(albedo, albedo, albedo, 1.0f);
  m.metallicFactor = 0.0f;
  m.roughnessFactor = 1.0f;
  m.specularFactor = 0.0f;
  return m;
}

inline void addTri(scene::Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material) {
  const uint32_t base = uint32_t(s.positions.size());
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  for (glm::vec3 p : {a, b, c}) {
    s.positions.push_back(p);
    s.normals.push_back(n);
    s.uvs.push_back(glm::vec2(0.0f));
    s.bounds.extend(p);
  }
  s.triangles.push_back({{base, base + 1, base + 2}, material});
}

// Registers every triangle of `material` as an area light.
inline void addAreaLights(scene::Scene& s, uint32_t material) {
  for (uint32_t t = 0; t < s.triangles.size(); ++t) {
    if (s.triangles[t].material != material) continue;
    const glm::vec3 a = s.positions[s.triangles[t].v[0]], b = s.positions[s.triangles[t].v[1]],
                    c = s.positions[s.triangles[t].v[2]];
    s.areaLights.push_back({t, 0.5f * glm::length(glm::cross(b - a, c - a))});
  }
}

// The square [-h, h]^2 in the plane y = 0, facing +y.
inline void addGround(scene::Scene& s, float h, uint32_t material) {
  addTri(s, {-h, 0, -h}, {-h, 0, h}, {h, 0, h}, material);
  addTri(s, {-h, 0, -h}, {h, 0, h}, {h, 0, -h}, material);
}

// A UV sphere, triangles wound counter-clockwise seen from outside, flat normals.
inline void addSphere(scene::Scene& s, glm::vec3 centre, float r, int segments, uint32_t material) {
  const int rings = segments / 2;
  auto point = [&](int i, int j) {
    const float theta = float(M_PI) * float(j) / float(rings), phi = 2.0f * float(M_PI) * float(i) / float(segments);
    return centre + r * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      const glm::vec3 a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1), d = point(i, j + 1);
      if (j > 0) addTri(s, a, b, d, material);
      if (j + 1 < rings) addTri(s, b, c, d, material);
    }
}

// A camera looking straight down from (0, height, 0): orthographic with half-height ymag, image
// top towards -z.
inline scene::Camera topDownOrtho(float height, float ymag) {
  scene::Camera c;
  c.projection = scene::Projection::Orthographic;
  c.ymag = ymag;
  c.xmag = ymag;
  c.cameraToWorld = glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0, 0, -1, 0), glm::vec4(0, 1, 0, 0), glm::vec4(0, height, 0, 1));
  return c;
}

inline scene::Camera perspectiveAt(glm::vec3 eye, float yfov) {
  scene::Camera c;
  c.yfov = yfov;
  c.cameraToWorld = glm::mat4(1.0f);
  c.cameraToWorld[3] = glm::vec4(eye, 1.0f);
  return c;
}

// A scene with its camera, for tests that run one check over several scenes.
struct ViewedScene {
  std::string name;
  scene::Scene scene;
  scene::Camera camera;
};

// Mirrors alone under the default light of a scene without lights, a uniform white
// environment (tools/lighting.cpp): a tinted mirror plane seen at an angle, and a lone mirror
// sphere. No surface sees another, yet every reflection sees the environment.
inline std::vector<ViewedScene> mirrorsUnderEnvironment() {
  scene::Material mirror;
  mirror.baseColorFactor = glm::vec4(0.9f, 0.6f, 0.3f, 1.0f);
  mirror.metallicFactor = 1.0f;
  mirror.roughnessFactor = 0.0f;
  const auto sky = std::make_shared<const scene::Environment>(scene::Environment::uniform(glm::vec3(1.0f), "uniform white"));
  std::vector<ViewedScene> out;
  ViewedScene plane{"mirror plane", {}, perspectiveAt({0.0f, 1.0f, 3.0f}, 0.9f)};
  addGround(plane.scene, 2.0f, addMaterial(plane.scene, mirror));
  plane.scene.environment = sky;
  out.push_back(std::move(plane));
  ViewedScene sphere{"mirror sphere", {}, perspectiveAt({0.0f, 0.0f, 4.0f}, 0.7f)};
  addSphere(sphere.scene, {0.0f, 0.0f, 0.0f}, 1.0f, 24, addMaterial(sphere.scene, mirror));
  sphere.scene.environment = sky;
  out.push_back(std::move(sphere));
  return out;
}

}  // namespace pr::test
