// Final gathering (seed chapter "Global Illumination in Complex Scenes using Photon Maps",
// section 2.4; Jensen 1996): the indirect irradiance at a diffuse point from a stratified
// hemisphere of rays whose hits are read from the global photon map, as one irradiance-cache
// record with its Ward-Heckbert gradients and the harmonic mean distance that sizes it. Runs
// in the photon-map integrator's pre-pass on a world-model PE (the scene and its BVH).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "photonmap/density_estimate.h"
#include "photonmap/irradiance_cache.h"
#include "photonmap/kd_tree.h"
#include "photonmap/precomputed_irradiance.h"
#include "raytrace/core/interaction.h"

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

// The radiance the global map estimates leaving a hit si towards si.wo: the Lambertian part
// (opaque weight x diffuse colour / pi) times the irradiance of the nearest photons, or of the
// nearest precomputed point when `precomputed` is given and not empty. Emission is not
// included (direct light is sampled at the gathering point).
glm::vec3 globalMapRadiance(const scene::Scene& scene, const KdTree& global, const PrecomputedIrradiance* precomputed,
                            const rt::SurfaceInteraction& si, const DensityOptions& density, bool textures,
                            NearestPhotons& scratch);

// Gathers the irradiance at si on the side of si.wo (shading normal) with options.rays rays
// stratified in (theta, phi) over the cosine-weighted hemisphere, Ward's E = pi/(MN) sum L_jk;
// radius is the harmonic mean distance of the hits (infinite when every ray escapes) before any
// clamping. id selects the random stream (the record's pixel). Adds the rays traced to rays.
IrradianceRecord gatherIrradiance(const scene::Scene& scene, const rt::Bvh& bvh, const KdTree& global,
                                  const rt::SurfaceInteraction& si, std::uint32_t id, const GatherOptions& options,
                                  NearestPhotons& scratch, std::uint64_t& rays);

}  // namespace pr::pm
