// IrradianceCache: Ward's irradiance cache (Ward, Rubinstein and Clear 1988) with the
// rotation and translation gradients of Ward and Heckbert (1992) and neighbour clamping
// (Krivanek et al. 2006), the structure that lets final gathering run at a small fraction of
// the pixels. A record holds the irradiance gathered at one point; the irradiance at a nearby
// point is the weighted mean of the records whose error estimate there is below the accuracy
// a, each extrapolated to the point by its gradients. Filled by the photon-map integrator's
// pre-pass on the controlling thread (records inserted in a fixed order, so the cache is the
// same for every P and schedule), then read-only by every PE.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"

namespace pr::pm {

struct IrradianceRecord {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};      // unit, on the side the irradiance was gathered
  glm::vec3 irradiance{0.0f};  // W m^-2 per channel
  float radius = 0.0f;         // R_i: the harmonic mean distance to the surfaces seen, clamped
  // d E_c / d(rotation) and d E_c / d(translation) per channel c, world space (Ward-Heckbert).
  glm::vec3 rotationGradient[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
  glm::vec3 translationGradient[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
};

class IrradianceCache {
 public:
  // bounds: the region records can lie in (the scene's); accuracy: Ward's a, the largest error
  // estimate eps_i(x) = |x - x_i| / R_i + sqrt(1 - n . n_i) at which record i is used.
  IrradianceCache(const scene::Bounds& bounds, float accuracy);
  IrradianceCache() : IrradianceCache(scene::Bounds{glm::vec3(0.0f), glm::vec3(1.0f)}, 0.2f) {}

  float accuracy() const { return accuracy_; }
  std::size_t size() const { return records_.size(); }
  const std::vector<IrradianceRecord>& records() const { return records_; }
  std::size_t bytes() const { return records_.size() * sizeof(IrradianceRecord) + nodes_.size() * sizeof(Node); }

  // Adds a record, first clamping radii against the records it overlaps (neighbour clamping:
  // R_i <= R_j + |x_i - x_j| both ways, so a record in a corner cannot reach past the
  // neighbour that saw the corner's nearer wall). The order of inserts decides the result.
  void insert(IrradianceRecord record);

  // The interpolated irradiance at x with unit normal n: false (and E untouched) when no record
  // is usable there (eps_i >= a, or the record lies in front of x). Weights w_i = 1/eps_i - 1/a
  // fall to zero at the edge of a record's reach, so the interpolation has no seams.
  bool lookup(const glm::vec3& x, const glm::vec3& n, glm::vec3& irradiance) const;
  bool covers(const glm::vec3& x, const glm::vec3& n) const;

 private:
  // An octree node (Ward 1988): a record lives in the smallest node containing its position
  // whose edge is at least twice its reach a R_i, so a query visits only the nodes whose cube,
  // grown by half its edge, contains the query point.
  struct Node {
    glm::vec3 centre{0.0f};
    float half = 0.0f;                // half the edge
    std::int32_t child[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
    std::vector<std::uint32_t> records;
  };
  // eps_i(x) and whether record i may be used at (x, n) at all.
  bool error(const IrradianceRecord& r, const glm::vec3& x, const glm::vec3& n, float& eps) const;
  template <class Fn>
  void visit(const glm::vec3& x, float grow, Fn&& fn) const;

  float accuracy_;
  std::vector<IrradianceRecord> records_;
  std::vector<Node> nodes_;
};

}  // namespace pr::pm
