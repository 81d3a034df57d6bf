// The photon map's estimates (density_estimate.h): the k-nearest search with the surface
// filter, then the box or cone density over the search disc.
#include "photonmap/density_estimate.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace pr::pm {

namespace {
constexpr float kPi = 3.14159265358979323846f;
}

float gatherSurfacePhotons(const KdTree& map, const glm::vec3& x, const glm::vec3& n, const DensityOptions& options,
                           NearestPhotons& scratch, int* rejectedOut, PhotonSelection selection) {
  scratch.neighbors.clear();
  scratch.radiusSq = 0.0f;
  const float maxRadius = options.maxRadius;
  if (options.k <= 0 || !(maxRadius > 0.0f) || map.empty()) return 0.0f;
  const float thickness = std::max(0.0f, options.discThickness) * maxRadius;

  // Reject photons of other surfaces while searching, so the k found are the k nearest of
  // this surface and the disc radius is theirs.
  int rejected = 0;
  auto onThisSurface = [&](const Photon& p) {
    if (!selection.accepts(p)) return false;
    const bool ok = std::abs(glm::dot(p.position - x, n)) <= thickness && glm::dot(p.incoming(), n) > 0.0f;
    rejected += ok ? 0 : 1;
    return ok;
  };
  map.nearest(x, options.k, maxRadius, onThisSurface, scratch);
  if (rejectedOut) *rejectedOut = rejected;
  const int found = static_cast<int>(scratch.size());
  if (found < std::max(1, options.minPhotons)) return 0.0f;
  // A zero-area disc (k photons exactly at x) has no density to speak of.
  if (!(scratch.radiusSq > 0.0f)) return 0.0f;
  // The cone's integral over the disc: int_0^r (1 - s/(kr)) 2 pi s ds = pi r^2 (1 - 2/(3k)).
  const float normalisation = options.filter == DensityFilter::Cone ? 1.0f - 2.0f / (3.0f * std::max(1.0f, options.coneK)) : 1.0f;
  return 1.0f / (normalisation * kPi * scratch.radiusSq);
}

float filterWeight(const DensityOptions& options, float distSq, float radiusSq) {
  if (options.filter != DensityFilter::Cone) return 1.0f;
  return 1.0f - std::sqrt(distSq / radiusSq) / std::max(1.0f, options.coneK);
}

DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options, NearestPhotons& scratch) {
  DensityEstimate result;
  const float scale = gatherSurfacePhotons(map, x, n, options, scratch, &result.rejected);
  result.radiusSq = scratch.radiusSq;
  if (!(scale > 0.0f)) return result;
  const std::span<const Photon> photons = map.photons();
  glm::vec3 sum(0.0f);
  for (const Neighbor& nb : scratch.neighbors)
    sum += filterWeight(options, nb.distSq, scratch.radiusSq) * photons[nb.index].powerRgb();
  const glm::vec3 irradiance = sum * scale;
  // A disc so small (r^2 near the float minimum) that the density overflows: no estimate.
  if (!std::isfinite(irradiance.x) || !std::isfinite(irradiance.y) || !std::isfinite(irradiance.z)) return result;
  result.irradiance = irradiance;
  result.photons = int(scratch.size());
  return result;
}

DensityEstimate estimateIrradiance(const KdTree& map, const glm::vec3& x, const glm::vec3& n,
                                   const DensityOptions& options) {
  NearestPhotons scratch;
  return estimateIrradiance(map, x, n, options, scratch);
}

}  // namespace pr::pm
