// Density estimation over a photon map: the irradiance (and Lambertian radiance) at a surface
// point from the k nearest photons, the photon map's answer in pass 2 (caustics straight from
// the caustic map, indirect diffuse at final-gather hits from the global map). Seed chapter
// "Global Illumination in Complex Scenes using Photon Maps", section 2.3, E = sum(Phi) / (pi R^2);
// the cone filter from Jensen, "Global Illumination using Photon Maps", EGWR 1996, section 4.
// Called on any PE, in any task, with a per-thread NearestPhotons as scratch.
#pragma once

#include <glm/glm.hpp>

#include "photonmap/kd_tree.h"

namespace pr::pm {

enum class DensityFilter {
  Box,   // every photon weighs 1 (global map: its estimate is smoothed by final gathering)
  Cone,  // weight 1 - d / (k r): sharper caustic edges (Jensen 1996)
};

struct DensityOptions {
  int k = 50;                 // photons gathered; Jensen uses 50-200 for the global map
  float maxRadius = 0.1f;     // world units; the seed's section 2.3 uses 0.1 m
  // Fewer accepted photons than this: no light (see estimateIrradiance).
  int minPhotons = 8;
  // A photon whose offset from x along n exceeds discThickness * maxRadius lies on another
  // surface (the other side of a thin wall, a parallel face). On a surface with radius of
  // curvature R a photon at tangential distance r lies r^2 / (2R) off the tangent plane, so
  // 0.1 keeps every photon of a surface curved down to R = 5 maxRadius.
  float discThickness = 0.1f;
  DensityFilter filter = DensityFilter::Box;
  float coneK = 1.1f;         // cone filter constant k >= 1 (Jensen: 1.1)
};

struct DensityEstimate {
  glm::vec3 irradiance{0.0f};  // W m^-2 per colour channel (photon power / area)
  int photons = 0;             // accepted photons that went into the estimate
  int rejected = 0;            // found in the sphere but on another surface or facing away
  float radiusSq = 0.0f;       // the disc of the estimate (NearestPhotons::radiusSq)
};

// Irradiance at x on a surface with unit normal n (the side the light is to be gathered on):
// gathers the k nearest photons within maxRadius, rejecting
//   - photons off the tangent disc, |dot(p - x, n)| > discThickness * maxRadius (thin walls:
//     photons on the back of a wall at x would otherwise light its front: light leaks), and
//   - back-face photons, dot(wi, n) <= 0: they arrived from the other side of the surface;
// then E = sum(w Phi) / (c pi r^2) with r^2 = NearestPhotons::radiusSq, w = 1 and c = 1 for the
// box filter, w = 1 - d / (k r) and c = 1 - 2 / (3k) for the cone filter (the cone's integral
// over the disc, int_0^r (1 - s/(kr)) 2 pi s ds = pi r^2 (1 - 2/(3k))).
// Returns exactly zero light, rather than noise, when fewer than minPhotons are accepted: the
// relative standard deviation of a count of N photons is 1/sqrt(N) (35 % at N = 8), and one
// stray photon in an otherwise dark maximum-radius disc makes a visible blotch; the light so
// dropped is less than minPhotons * maxPhotonPower / (pi maxRadius^2), a sparse region's worth.
// Also zero for a zero-area disc (r = 0: maxRadius 0, or k photons all at x), k <= 0 or an
// empty map; never NaN or Inf for finite inputs.
DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options, NearestPhotons& scratch);
DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options);

// Outgoing radiance of a Lambertian surface of the given albedo under irradiance E:
// L = (albedo / pi) E (the seed's section 2.3, f_r = rho_d / pi).
inline glm::vec3 lambertianRadiance(const glm::vec3& albedo, const glm::vec3& irradiance) {
  constexpr float kInvPi = 0.318309886183790671538f;
  return albedo * kInvPi * irradiance;
}

}  // namespace pr::pm
