// The `landscape` scene: Jensen 1996, figure 4. A fractal terrain (fBm of seeded Perlin
// noise sampled on a regular grid) lit by a spherical light both directly and through a
// lens-shaped glass ellipsoid between them, which focuses a caustic onto the terrain.
// Large (1M triangles at the default size): written as .glb, not committed.
#include <cmath>
#include <numbers>

#include "tools/scenegen/noise.h"
#include "tools/scenegen/scene_registry.h"

namespace pr::scenegen {
namespace {

constexpr float kExtent = 40.0f;           // terrain covers [-20, 20]^2 in x and z
constexpr float kFeatureFrequency = 0.1f;  // lowest octave: hills about 10 units across
constexpr int kOctaves = 8;                // finest octave ~0.08 units, about 1.5 cells at size 708
constexpr float kHeightScale = 6.0f;       // |height| <= 6 * sqrt(2)/2 = 4.24, below the lens (5.5)

// Lens: a flattened sphere with semi-axes a = 1.5 (horizontal) and c = 0.5 (vertical). Its
// surfaces have curvature radius R = a^2 / c = 4.5 on the axis; as a thick biconvex lens of
// ior n = 1.5 and thickness t = 2c: 1/f = (n-1) (2/R - (n-1) t / (n R^2)) gives f = 4.67.
// With the lens 6 units above the terrain's mean height (0 at the origin, where every
// octave's lattice value is 0), 1/d_o = 1/f - 1/6 puts the light 21 units above the lens.
constexpr glm::vec3 kLensCenter{0.0f, 6.0f, 0.0f};
constexpr glm::vec3 kLensRadii{1.5f, 0.5f, 1.5f};
constexpr glm::vec3 kLightCenter{0.0f, 27.0f, 0.0f};
constexpr float kLightRadius = 0.5f;
// Irradiance from a sphere of radiance L and radius r at distance d is pi L (r/d)^2
// = 0.00108 L at the terrain; L = 2000 gives about 2, a bright sunlit look for albedo ~0.5.
constexpr float kLightStrength = 2000.0f;

}  // namespace

void buildLandscape(GltfBuilder& b, const SceneParams& params) {
  const int terrainMaterial = b.addMaterial({.name = "terrain", .baseColor = {0.55f, 0.5f, 0.4f, 1.0f}, .specular = 0.0f});
  const int glass = b.addMaterial(
      {.name = "lens glass", .baseColor = glm::vec4(1.0f), .roughness = 0.0f, .transmission = 1.0f, .ior = 1.5f});
  const int light = b.addMaterial({.name = "light",
                                   .baseColor = {0.0f, 0.0f, 0.0f, 1.0f},
                                   .emissive = glm::vec3(1.0f),
                                   .emissiveStrength = kLightStrength,
                                   .specular = 0.0f});

  const PerlinNoise noise(params.seed);
  const float half = kExtent / 2;
  const MeshData terrain = makeHeightField(params.size, -half, -half, kExtent, [&](float x, float z) {
    return kHeightScale * noise.fbm(x * kFeatureFrequency, z * kFeatureFrequency, kOctaves);
  });
  b.addMeshNode("terrain", b.addMesh("terrain", terrain, terrainMaterial));
  b.addMeshNode("lens", b.addMesh("lens", makeEllipsoid(kLensCenter, kLensRadii, 64, 32), glass));
  b.addMeshNode("light", b.addMesh("light", makeEllipsoid(kLightCenter, glm::vec3(kLightRadius), 32, 16), light));

  // Camera high above the terrain's front half looking 57 degrees down at the caustic under
  // the lens; the lens shows above the caustic, the light is out of view. yfov 40 degrees at
  // 4:3 keeps the whole image on the terrain: the top corners' rays meet height -2 (below
  // the terrain at seed 1) at |x| = 16.7, z = -17.2, inside the [-20, 20] square.
  b.addPerspectiveCamera("camera", 40.0f * std::numbers::pi_v<float> / 180.0f, 4.0f / 3.0f, 0.1f, 200.0f,
                         {0.0f, 20.0f, 12.0f}, {0.0f, 0.0f, -1.0f});
}

}  // namespace pr::scenegen
