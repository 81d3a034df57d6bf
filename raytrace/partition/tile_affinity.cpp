// The probes and votes of tile_affinity.h.
#include "raytrace/partition/tile_affinity.h"

#include <algorithm>

#include "common/util/error.h"

namespace pr::rt {

std::vector<Ray> affinityProbes(const Integrator& integrator, std::span<const PixelRect> tiles) {
  std::vector<Ray> probes;
  probes.reserve(tiles.size() * kAffinityProbesPerTile);
  std::vector<RayMessage> camera;
  for (const PixelRect& t : tiles) {
    for (int j = 0; j < kAffinityProbesPerEdge; ++j) {
      for (int i = 0; i < kAffinityProbesPerEdge; ++i) {
        // The centre of quarter (i, j), clamped into tiles narrower than the probe grid.
        const int x = std::min(t.x1 - 1, t.x0 + (2 * i + 1) * (t.x1 - t.x0) / (2 * kAffinityProbesPerEdge));
        const int y = std::min(t.y1 - 1, t.y0 + (2 * j + 1) * (t.y1 - t.y0) / (2 * kAffinityProbesPerEdge));
        camera.clear();
        integrator.cameraRays(PixelRect{x, y, x + 1, y + 1}, 1, camera);
        PR_CHECK(!camera.empty(), "affinityProbes: no camera ray for a probe pixel");
        probes.push_back(camera.front().ray);
      }
    }
  }
  return probes;
}

std::vector<int> nearestOwners(const std::vector<std::vector<float>>& nearest, std::span<const float> shared) {
  const std::size_t probes = nearest.empty() ? shared.size() : nearest.front().size();
  for (const std::vector<float>& n : nearest) PR_CHECK(n.size() == probes, "nearestOwners: one hit per probe per PE");
  PR_CHECK(shared.empty() || shared.size() == probes, "nearestOwners: one shared hit per probe");
  std::vector<int> owner(probes, -1);
  for (std::size_t i = 0; i < probes; ++i) {
    float best = shared.empty() ? kInfinity : shared[i];
    for (std::size_t p = 0; p < nearest.size(); ++p)
      if (nearest[p][i] < best) {
        best = nearest[p][i];
        owner[i] = int(p);
      }
  }
  return owner;
}

std::vector<int> preferredPes(std::span<const int> probeOwner, std::size_t tiles, int pes) {
  PR_CHECK(probeOwner.size() == tiles * kAffinityProbesPerTile, "preferredPes: kAffinityProbesPerTile probes per tile");
  std::vector<int> preferred(tiles, -1);
  std::vector<int> votes(static_cast<std::size_t>(pes));
  for (std::size_t t = 0; t < tiles; ++t) {
    std::fill(votes.begin(), votes.end(), 0);
    for (std::size_t i = t * kAffinityProbesPerTile; i < (t + 1) * kAffinityProbesPerTile; ++i) {
      PR_CHECK(probeOwner[i] < pes, "preferredPes: a probe's owner outside [0, P)");
      if (probeOwner[i] >= 0) ++votes[size_t(probeOwner[i])];
    }
    const auto most = std::max_element(votes.begin(), votes.end());  // the first of equals
    if (most != votes.end() && *most > 0) preferred[t] = int(most - votes.begin());
  }
  return preferred;
}

}  // namespace pr::rt
