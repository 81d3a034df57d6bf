// The photon map's irradiance estimate (density_estimate.h): the k-nearest search with the
// surface filter, then the box or cone density over the search disc.
#include "photonmap/density_estimate.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace pr::pm {

DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options, NearestPhotons& scratch) {
  DensityEstimate result;
  const float maxRadius = options.maxRadius;
  if (options.k <= 0 || !(maxRadius > 0.0f) || map.empty()) return result;
  const float thickness = std::max(0.0f, options.discThickness) * maxRadius;

  // Step 1: gather, rejecting photons of other surfaces while searching, so the k found are
  // the k nearest of this surface and the disc radius is theirs.
  int rejected = 0;
  auto onThisSurface = [&](const Photon& p) {
    const bool ok = std::abs(glm::dot(p.position - x, n)) <= thickness && glm::dot(p.incoming(), n) > 0.0f;
    rejected += ok ? 0 : 1;
    return ok;
  };
  map.nearest(x, options.k, maxRadius, onThisSurface, scratch);
  result.rejected = rejected;
  result.radiusSq = scratch.radiusSq;
  const int found = static_cast<int>(scratch.size());
  if (found < std::max(1, options.minPhotons)) return result;  // too few: no light, not noise
  // A zero-area disc (k photons exactly at x) has no density to speak of.
  if (!(scratch.radiusSq > 0.0f)) return result;

  // Step 2: the density, E = sum(w Phi) / (c pi r^2).
  const std::span<const Photon> photons = map.photons();
  constexpr float kPi = 3.14159265358979323846f;
  glm::vec3 sum(0.0f);
  float normalisation = 1.0f;
  if (options.filter == DensityFilter::Cone) {
    const float k = std::max(1.0f, options.coneK);
    const float invKr = 1.0f / (k * std::sqrt(scratch.radiusSq));
    for (const Neighbor& nb : scratch.neighbors)
      sum += (1.0f - std::sqrt(nb.distSq) * invKr) * photons[nb.index].powerRgb();
    normalisation = 1.0f - 2.0f / (3.0f * k);
  } else {
    for (const Neighbor& nb : scratch.neighbors) sum += photons[nb.index].powerRgb();
  }
  const glm::vec3 irradiance = sum / (normalisation * kPi * scratch.radiusSq);
  // A disc so small (r^2 near the float minimum) that the density overflows: no estimate.
  if (!std::isfinite(irradiance.x) || !std::isfinite(irradiance.y) || !std::isfinite(irradiance.z)) return result;
  result.irradiance = irradiance;
  result.photons = found;
  return result;
}

DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options) {
  NearestPhotons scratch;
  return estimateIrradiance(map, x, n, options, scratch);
}

}  // namespace pr::pm
