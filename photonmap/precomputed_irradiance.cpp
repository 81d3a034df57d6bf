// Precomputed irradiance at photon positions (see precomputed_irradiance.h).
#include "photonmap/precomputed_irradiance.h"

#include <algorithm>
#include <vector>

#include "common/parallel/gather_to_root.h"
#include "common/parallel/runtime.h"

namespace pr::pm {

namespace {
// Points per task of the build.
constexpr std::size_t kPointsPerTask = 2048;
// A point serves a query whose normal is within acos(0.9) ~ 25 degrees of its own.
constexpr float kSameSurfaceCos = 0.9f;
}  // namespace

PrecomputedIrradiance PrecomputedIrradiance::build(const std::vector<Photon>& photons,
                                                   const std::vector<glm::vec3>& normals, const KdTree& global,
                                                   const DensityOptions& density, int stride, par::Runtime& runtime) {
  PrecomputedIrradiance out;
  const std::size_t step = std::size_t(std::max(1, stride));
  const std::size_t count = std::min(photons.size(), normals.size()) == 0 ? 0 : (photons.size() + step - 1) / step;
  if (count == 0 || normals.size() != photons.size()) return out;
  std::vector<Photon> points(count);
  // Across ranks each rank computes its PEs' points: every rank gets them all.
  par::runStageSharingResults(runtime, "precompute irradiance", "precomputed irradiance merge", "irradiance points", points,
                              kPointsPerTask, [&](par::Pe&, par::TaskId task) {
    NearestPhotons scratch;
    const std::size_t begin = std::size_t(task) * kPointsPerTask, end = std::min(count, begin + kPointsPerTask);
    for (std::size_t i = begin; i < end; ++i) {
      const Photon& p = photons[i * step];
      const glm::vec3& n = normals[i * step];
      const DensityEstimate e = estimateIrradiance(global, p.position, n, density, scratch);
      points[i] = Photon::make(p.position, e.irradiance, n);
    }
  });
  out.points_ = KdTree::build(std::move(points), runtime);
  return out;
}

glm::vec3 PrecomputedIrradiance::irradiance(const glm::vec3& x, const glm::vec3& n, float maxRadius,
                                            NearestPhotons& scratch) const {
  points_.nearest(x, 1, maxRadius, [&](const Photon& p) { return glm::dot(p.incoming(), n) > kSameSurfaceCos; }, scratch);
  if (scratch.empty()) return glm::vec3(0.0f);
  return points_.photons()[scratch.neighbors.front().index].powerRgb();
}

}  // namespace pr::pm
