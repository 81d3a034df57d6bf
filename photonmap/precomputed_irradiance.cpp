// Precomputed irradiance at photon positions (see precomputed_irradiance.h).
#include "photonmap/precomputed_irradiance.h"

#include <algorithm>
#include <vector>

#include "common/parallel/runtime.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/interaction.h"

namespace pr::pm {

namespace {
// Points per task of the build.
constexpr std::size_t kPointsPerTask = 2048;
// A point serves a query whose normal is within acos(0.9) ~ 25 degrees of its own.
constexpr float kSameSurfaceCos = 0.9f;
}  // namespace

PrecomputedIrradiance PrecomputedIrradiance::build(const scene::Scene& scene, const rt::Bvh& bvh, const KdTree& global,
                                                   const DensityOptions& density, int stride, par::Runtime& runtime) {
  PrecomputedIrradiance out;
  const std::size_t step = std::size_t(std::max(1, stride));
  const std::size_t count = (global.size() + step - 1) / step;
  if (count == 0) return out;
  // The probe ray's length: far above float rounding at the scene's scale, far below any
  // feature size (1e-4 of the scene's diagonal).
  const float probe = 1.0e-4f * std::max(glm::length(scene.bounds.extent()), 1.0e-6f);
  const std::size_t tasks = (count + kPointsPerTask - 1) / kPointsPerTask;
  std::vector<std::vector<Photon>> chunks(tasks);
  runtime.runStage("precompute irradiance", par::TaskSet::uniform(tasks), [&](par::Pe&, par::TaskId task) {
    NearestPhotons scratch;
    std::vector<Photon>& chunk = chunks[std::size_t(task)];
    const std::size_t begin = std::size_t(task) * kPointsPerTask, end = std::min(count, begin + kPointsPerTask);
    for (std::size_t i = begin; i < end; ++i) {
      const Photon& p = global.photons()[i * step];
      const glm::vec3 wi = p.incoming();
      // From just above the surface back down onto it: the hit's geometric normal, turned to
      // the side the photon arrived from.
      const rt::Ray ray{p.position + probe * wi, 0.0f, -wi, 2.0f * probe};
      rt::Hit hit;
      if (!bvh.intersect(ray, hit)) continue;
      const rt::SurfaceInteraction si = rt::makeInteraction(scene, ray, hit);
      const glm::vec3 n = glm::dot(si.geometricNormal, wi) >= 0.0f ? si.geometricNormal : -si.geometricNormal;
      const DensityEstimate e = estimateIrradiance(global, p.position, n, density, scratch);
      chunk.push_back(Photon::make(p.position, e.irradiance, n));
    }
  });
  std::vector<Photon> points;
  for (const std::vector<Photon>& c : chunks) points.insert(points.end(), c.begin(), c.end());
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
