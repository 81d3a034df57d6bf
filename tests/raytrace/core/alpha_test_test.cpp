// The ray tracers' share of the alpha modes and vertex colours: a MASK surface below its
// cutoff is not hit by closest-hit or shadow queries (the surface behind is), BLEND lets
// through a fraction 1 - alpha of the rays, and COLOR_0 reaches the material at a hit.
#include <doctest/doctest.h>

#include <cmath>

#include "raytrace/core/bvh.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/bsdf.h"

using namespace pr;

namespace {

// Two quads facing +z: material 0 at z = 1 (alpha-cut), material 1 at z = 0.
scene::Scene twoQuads(scene::AlphaMode mode, float alpha) {
  scene::Scene s;
  scene::Material front, back;
  front.baseColorFactor = glm::vec4(1, 0, 0, alpha);
  front.alphaMode = mode;
  s.materials = {front, back, scene::Material{}};
  for (auto [z, m] : {std::pair{1.0f, 0u}, std::pair{0.0f, 1u}}) {
    const uint32_t b = uint32_t(s.positions.size());
    s.positions.insert(s.positions.end(), {{-1, -1, z}, {1, -1, z}, {1, 1, z}, {-1, 1, z}});
    s.triangles.push_back({{b, b + 1, b + 2}, m});
    s.triangles.push_back({{b, b + 2, b + 3}, m});
  }
  return s;
}

rt::Ray down(float x, float y) { return rt::Ray{glm::vec3(x, y, 5.0f), 0.0f, glm::vec3(0, 0, -1), rt::kInfinity}; }

}  // namespace

TEST_CASE("AlphaTest: MASK below the cutoff is invisible to closest-hit and shadow rays") {
  const scene::Scene cut = twoQuads(scene::AlphaMode::Mask, 0.3f);
  const rt::Bvh bvh(cut);
  rt::Hit hit;
  REQUIRE(bvh.intersect(down(0.2f, 0.1f), hit));
  CHECK(cut.triangles[hit.triangle].material == 1);
  // A shadow ray ending between the two quads passes the cut one.
  rt::Ray shadow = down(0.2f, 0.1f);
  shadow.tMax = 4.5f;
  CHECK_FALSE(bvh.occluded(shadow));
  // Above the cutoff the front quad is there.
  const scene::Scene solid = twoQuads(scene::AlphaMode::Mask, 0.7f);
  const rt::Bvh solidBvh(solid);
  REQUIRE(solidBvh.intersect(down(0.2f, 0.1f), hit));
  CHECK(solid.triangles[hit.triangle].material == 0);
  CHECK(solidBvh.occluded(shadow));
}

TEST_CASE("AlphaTest: BLEND stops a fraction alpha of the rays, the same ray always alike") {
  const scene::Scene s = twoQuads(scene::AlphaMode::Blend, 0.4f);
  const rt::Bvh bvh(s);
  int front = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    rt::Hit a, b;
    const rt::Ray r = down(-0.9f + 1.8f * float(i % 50) / 50.0f, -0.9f + 1.8f * float(i / 50) / 40.0f);
    REQUIRE(bvh.intersect(r, a));
    REQUIRE(bvh.intersect(r, b));
    CHECK(a.triangle == b.triangle);
    front += s.triangles[a.triangle].material == 0 ? 1 : 0;
  }
  // 2000 rays: sigma = sqrt(2000 * 0.24) = 22.
  CHECK(std::abs(front - int(0.4f * n)) < 70);
}

TEST_CASE("AlphaTest: COLOR_0 multiplies the base colour at a ray hit") {
  scene::Scene s = twoQuads(scene::AlphaMode::Opaque, 1.0f);
  s.materials[0].baseColorFactor = glm::vec4(1.0f);
  s.colors.assign(s.positions.size(), glm::vec4(1.0f));
  for (int v = 0; v < 4; ++v) s.colors[size_t(v)] = glm::vec4(0.25f, 0.5f, 1.0f, 1.0f);
  const rt::Bvh bvh(s);
  rt::Hit hit;
  const rt::Ray r = down(0.2f, 0.1f);
  REQUIRE(bvh.intersect(r, hit));
  const rt::SurfaceInteraction si = rt::makeInteraction(s, r, hit);
  const rt::ShadingMaterial m = rt::evalMaterial(s, si);
  CHECK(m.baseColor.x == doctest::Approx(0.25f));
  CHECK(m.baseColor.y == doctest::Approx(0.5f));
}
