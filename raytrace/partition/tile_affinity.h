// Tile affinity: the data-aware conceptual regions of the preferred-bias schedule (seed 3.4.5)
// for the data-partitioned tracers. A few probe camera rays per tile stand for its rays; in
// object partitioning every owner traces them against its own geometry in the build stage and
// the nearest hits are gathered on PE 0 (gather_to_root.h), where the scheduler reads them;
// object-space walks them through the replicated kd tree. The owner most of a tile's probes
// reach first is the tile's preferred PE (TaskInfo::preferredPe): a tile that starts there has
// its camera rays answered by the originator's own data, and so do most of the rays they spawn
// nearby, instead of each going to another PE. The probes are a pure function of the camera
// and the tiles, so the regions, like the image, do not depend on timing.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "raytrace/core/ray.h"
#include "raytrace/integrators/film.h"
#include "raytrace/integrators/integrator.h"

namespace pr::rt {

// Probe pixels per tile edge: the centres of the tile's 2 x 2 quarters.
inline constexpr int kAffinityProbesPerEdge = 2;
inline constexpr int kAffinityProbesPerTile = kAffinityProbesPerEdge * kAffinityProbesPerEdge;

// kAffinityProbesPerTile rays per tile, in tile order: the first camera ray of each probe pixel.
std::vector<Ray> affinityProbes(const Integrator& integrator, std::span<const PixelRect> tiles);

// nearest[p][i]: the nearest hit of probe i on PE p's own geometry (kInfinity: none); shared[i]
// the same on geometry every PE holds (empty: none such). Per tile: the PE whose geometry most
// of its probes hit first (ties: the lower PE), or -1 when no probe hits owned geometry first.
std::vector<int> preferredPes(const std::vector<std::vector<float>>& nearest, std::span<const float> shared,
                              std::size_t tiles);

}  // namespace pr::rt
