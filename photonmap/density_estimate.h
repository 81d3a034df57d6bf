// Density estimation over a photon map: the irradiance (and Lambertian radiance) at a surface
// point from the k nearest photons, the photon map's answer in pass 2 (caustics straight from
// the caustic map, indirect diffuse at final-gather hits from the global map). Seed chapter
// "Global Illumination in Complex Scenes using Photon Maps", section 2.3, E = sum(Phi) / (pi R^2);
// the cone filter from Jensen, "Global Illumination using Photon Maps", EGWR 1996, section 4.
// Called on any PE, in any task, with a per-thread NearestPhotons as scratch.
#pragma once

#include <cmath>
#include <cstdint>

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
  // Fewer accepted photons than this: no light (see estimateIrradiance). 1 by default: a
  // search that finds fewer than k photons covers the whole maximum disc, and the count in a
  // fixed disc is an unbiased estimate however small it is.
  int minPhotons = 1;
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
// Where fewer than k photons lie within maxRadius the disc is the whole maximum one, so a sparse
// region (a caustic's faint edge) gets its photons' power over pi maxRadius^2: the mean of a
// fixed-disc count is the disc's mean irradiance, however few photons it holds (a rule that
// returned zero below some count would trim every faint region). Zero when fewer than
// minPhotons are accepted, for a zero-area disc (r = 0: maxRadius 0, or k photons all at x),
// k <= 0 or an empty map; never NaN or Inf for finite inputs.
DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options, NearestPhotons& scratch);
DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options);

// Which photons an estimate reads, by the reflections their paths took (PhotonPath bits):
// those with every bit of `all` and none of `none`; every photon by default.
struct PhotonSelection {
  std::uint8_t all = 0, none = 0;
  bool accepts(const Photon& p) const { return (p.path() & all) == all && (p.path() & none) == 0; }
};

// The k nearest selected photons of the surface at x into scratch, as estimateIrradiance
// gathers them, and the factor 1 / (c pi r^2) that turns their filter-weighted power into a
// density (0 when there is no estimate: too few photons, a zero-area disc). rejected: photons
// of other surfaces.
float gatherSurfacePhotons(const KdTree& map, const glm::vec3& x, const glm::vec3& n, const DensityOptions& options,
                           NearestPhotons& scratch, int* rejected = nullptr, PhotonSelection selection = {});
// A gathered photon's filter weight: 1 for the box, 1 - d / (k r) for the cone.
float filterWeight(const DensityOptions& options, float distSq, float radiusSq);

// Reflected radiance from the same photons with the BRDF of each one's stored direction
// (Jensen 1996: L = sum f_r(x, w_p, w) Phi_p / (pi r^2)): brdf(photon) is f_r towards the viewer
// for the photon's incoming() direction (world, back towards where it came from). What a
// non-Lambertian surface (a glossy lobe, sheen, a clear coat) reflects of the light the
// photons bring.
template <class Brdf>
glm::vec3 estimateRadiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n, const DensityOptions& options,
                           NearestPhotons& scratch, const Brdf& brdf, PhotonSelection selection = {}) {
  const float scale = gatherSurfacePhotons(map, x, n, options, scratch, nullptr, selection);
  if (!(scale > 0.0f)) return glm::vec3(0.0f);
  glm::vec3 sum(0.0f);
  for (const Neighbor& nb : scratch.neighbors) {
    const Photon& p = map.photons()[nb.index];
    sum += filterWeight(options, nb.distSq, scratch.radiusSq) * brdf(p) * p.powerRgb();
  }
  const glm::vec3 radiance = sum * scale;
  return std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z) ? radiance : glm::vec3(0.0f);
}

// Outgoing radiance of a Lambertian surface of the given albedo under irradiance E:
// L = (albedo / pi) E (the seed's section 2.3, f_r = rho_d / pi).
inline glm::vec3 lambertianRadiance(const glm::vec3& albedo, const glm::vec3& irradiance) {
  constexpr float kInvPi = 0.318309886183790671538f;
  return albedo * kInvPi * irradiance;
}

}  // namespace pr::pm
