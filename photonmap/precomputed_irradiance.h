// Precomputed irradiance (Christensen, "Faster Photon Map Global Illumination", 1999): the
// global map's irradiance estimate computed once at every n-th stored photon and kept, with the
// surface normal there, in a kd-tree of its own. A final-gather hit then reads the nearest such
// point on its surface - one 1-nearest search - instead of a k-nearest density estimate: the
// estimate the gather averages hundreds of times per record is paid once per point.
// Built in the photon-map integrator's pre-pass on the runtime; read-only by every PE after.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "photonmap/density_estimate.h"
#include "photonmap/kd_tree.h"

namespace pr::par {
class Runtime;
}

namespace pr::pm {

class PrecomputedIrradiance {
 public:
  PrecomputedIrradiance() = default;
  // Every stride-th photon of `photons` (the global map's photons in merge order, with the
  // normals of the surfaces they were stored on) becomes a point, its irradiance estimated over
  // `global` (the kd-tree built from them) with `density`. One task per chunk of points on the
  // runtime (stage "precompute irradiance"); the points keep the photons' order, so the
  // structure is the same for every tracer, P and schedule.
  static PrecomputedIrradiance build(const std::vector<Photon>& photons, const std::vector<glm::vec3>& normals,
                                     const KdTree& global, const DensityOptions& density, int stride,
                                     par::Runtime& runtime);

  bool empty() const { return points_.empty(); }
  std::size_t size() const { return points_.size(); }
  std::size_t bytes() const { return points_.bytes(); }

  // The irradiance of the nearest point within maxRadius whose normal is within ~25 degrees of
  // n (a point of the same surface); zero when there is none.
  glm::vec3 irradiance(const glm::vec3& x, const glm::vec3& n, float maxRadius, NearestPhotons& scratch) const;

 private:
  KdTree points_;  // Photon records: power = irradiance (RGBE), direction = surface normal
};

}  // namespace pr::pm
