// Precomputed irradiance (Christensen, "Faster Photon Map Global Illumination", 1999): the
// global map's irradiance estimate computed once at every n-th stored photon and kept, with the
// surface normal there, in a kd-tree of its own. A final-gather hit then reads the nearest such
// point on its surface - one 1-nearest search - instead of a k-nearest density estimate: the
// estimate the gather averages hundreds of times per record is paid once per point.
// Built in the photon-map integrator's pre-pass on the runtime; read-only by every PE after.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "photonmap/density_estimate.h"
#include "photonmap/kd_tree.h"

namespace pr::par {
class Runtime;
}
namespace pr::rt {
class Bvh;
}

namespace pr::pm {

class PrecomputedIrradiance {
 public:
  PrecomputedIrradiance() = default;
  // Every stride-th photon of `global` (heap order) becomes a point: its surface normal found
  // by a short ray back along the photon's incoming direction (a photon whose surface the ray
  // misses is skipped), its irradiance estimated over `global` with `density`. One task per
  // chunk of photons on the runtime (stage "precompute irradiance"); the points are kept in
  // photon order, so the structure is the same for every P and schedule.
  static PrecomputedIrradiance build(const scene::Scene& scene, const rt::Bvh& bvh, const KdTree& global,
                                     const DensityOptions& density, int stride, par::Runtime& runtime);

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
