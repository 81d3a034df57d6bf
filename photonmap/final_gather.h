// Final gathering (seed chapter "Global Illumination in Complex Scenes using Photon Maps",
// section 2.4; Jensen 1996): the indirect irradiance at a diffuse point from a stratified
// hemisphere of rays whose hits are read from the global photon map, as one irradiance-cache
// record with its Ward-Heckbert gradients and the harmonic mean distance that sizes it. The
// pieces - the ray directions, one interaction of a gather ray, the record from the cells -
// are run by the irradiance cache's pre-pass program through any tracer; gatherIrradiance runs
// them in one go over a world BVH.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "photonmap/density_estimate.h"
#include "photonmap/irradiance_cache.h"
#include "photonmap/kd_tree.h"
#include "photonmap/precomputed_irradiance.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/integrator.h"

namespace pr::rt {
class Bvh;
}

namespace pr::pm {

struct GatherOptions {
  int rays = 256;             // hemisphere rays per record, as M x N strata with N ~ pi M
  int specularBounces = 4;    // ideal mirror / glass bounces a gather ray follows to a diffuse surface
  DensityOptions global;      // the global map's estimate at the gather hits
  // When given (not empty): the gather hits read it instead of a density estimate each.
  const PrecomputedIrradiance* precomputed = nullptr;
  bool textures = true;       // the plan's textures
  std::uint64_t seed = 1;
};

// What a photon-map read at a hit stands for, in Jensen's split of the light a point receives
// (direct, caustic, glossy-caustic, indirect; photon.h's PhotonPath):
enum class MapRead {
  // Every photon (the map views; the caustic map at an eye point, whose photons came along
  // ideal specular paths only).
  All,
  // A gather or glossy ray's hit: the light leaving it towards the ray's origin after a diffuse
  // bounce. The diffuse part reads every photon (its own reflection is that bounce); the
  // non-Lambertian lobes only photons whose paths took a diffuse bounce - light that came
  // along glossy and specular bounces alone is the receiver's glossy-caustic term.
  Secondary,
  // An eye point's glossy caustics: the global map's photons whose paths took a glossy bounce
  // but no diffuse one (light a rough metal throws onto a wall), read where they land.
  GlossyCaustic,
};

// The radiance a photon map estimates leaving a hit si towards si.wo for `read` (sf: its
// shading frame, made with m, which it turns to the anisotropy and coat frames): Jensen's
// estimate with the full non-delta BRDF of the opaque part and each photon's direction. In a
// Secondary read an exactly Lambertian part reads the photons' irradiance times diffuse colour
// / pi - from the nearest precomputed point when `precomputed` is given and not empty - and a
// rough specular lobe is read only when `roulette` < its share of the reflectance (at least
// 1/10) and then divided by that share, which keeps the mean and spares a search where the
// lobe is a faint 4 % layer. Emission is not included (direct light is sampled where the ray
// started).
glm::vec3 mapRadiance(const rt::ShadingMaterial& m, const rt::ShadingFrame& sf, const KdTree& map,
                      const PrecomputedIrradiance* precomputed, const rt::SurfaceInteraction& si,
                      const DensityOptions& density, NearestPhotons& scratch, MapRead read = MapRead::All,
                      float roulette = 0.0f);
// How a gathering (or glossy) path goes on through a specular surface at si to the diffuse
// surface behind it, with u in [0, 1): through the dielectric part with probability its weight
// (rt::sampleDielectric: Fresnel's choice, which cancels its weight; a refraction tinted as eye
// paths tint it; frosted glass about a GGX microfacet normal drawn for (mu, mv)), else an
// opaque ideal mirror's reflection, its Fresnel weight over its selection probability
// 1 - dielectric. wi and the factor that multiplies the path's throughput; false when there
// is no such part to follow or the sample is lost.
bool specularBounce(const rt::ShadingMaterial& m, const rt::SurfaceInteraction& si, const rt::ShadingFrame& sf, float u,
                    float mu, float mv, glm::vec3& wi, glm::vec3& factor);

// The M x N (theta, phi) strata of a record's rays: M = round(sqrt(rays / pi)), N = round(rays / M).
struct GatherStrata {
  int m = 1, n = 1;
  int cells() const { return m * n; }
};
GatherStrata gatherStrata(int rays);

// Ray j of record `id` leaving si (its shading frame sf): cell (j / N, j % N), cosine-weighted
// and jittered; false when it points below the geometric surface (the cell stays dark).
bool gatherRay(const rt::SurfaceInteraction& si, const rt::ShadingFrame& sf, GatherStrata strata, std::uint32_t id,
               std::uint32_t j, const GatherOptions& options, rt::Ray& ray);

// One hit of a gather ray (its bounce-th, through ideal mirrors and glass) that arrived along
// ray: the global map's radiance there times the ray's throughput (attenuated by Beer-Lambert
// when the ray ran inside an absorbing solid, as eye paths are), and the ray it goes on as.
struct GatherInteraction {
  glm::vec3 radiance{0.0f};
  bool continues = false;
  rt::Ray next;
  glm::vec3 throughput{0.0f};
};
GatherInteraction gatherInteraction(const scene::Scene& scene, const KdTree& global, const rt::SurfaceInteraction& si,
                                    const rt::Ray& ray, glm::vec3 throughput, std::uint32_t id, std::uint32_t j, int bounce,
                                    const GatherOptions& options, NearestPhotons& scratch);

// What a record's ray j brought back: its radiance (summed over its hits in bounce order) and
// the distance to its first hit (infinite when it left the scene).
struct GatherCell {
  glm::vec3 radiance{0.0f};
  float distance = std::numeric_limits<float>::infinity();
};

// The record from its cells (strata.cells() of them, in ray order): E = pi/(MN) sum L, the
// rotation and translation gradients, and the harmonic mean distance as radius (unclamped).
IrradianceRecord combineGather(const rt::SurfaceInteraction& si, const rt::ShadingFrame& sf, GatherStrata strata,
                               std::uint32_t id, const GatherOptions& options, std::span<const GatherCell> cells);

// All of it over a world BVH on the calling thread: the record at si on the side of si.wo.
// id selects the random stream (the record's pixel). Adds the rays traced to rays.
IrradianceRecord gatherIrradiance(const scene::Scene& scene, const rt::Bvh& bvh, const KdTree& global,
                                  const rt::SurfaceInteraction& si, std::uint32_t id, const GatherOptions& options,
                                  NearestPhotons& scratch, std::uint64_t& rays);

}  // namespace pr::pm
