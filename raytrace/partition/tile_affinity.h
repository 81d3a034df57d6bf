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
// the same on geometry every PE holds (empty: none such). Per probe: the PE whose geometry it
// hits first (ties: the lower PE), or -1 when it hits none or the shared geometry first.
std::vector<int> nearestOwners(const std::vector<std::vector<float>>& nearest, std::span<const float> shared);

// probeOwner[i]: the PE that answers probe i first, or -1 (nearestOwners). Per tile: the PE
// most of its probes name (ties: the lower PE), or -1 when none names one.
std::vector<int> preferredPes(std::span<const int> probeOwner, std::size_t tiles, int pes);

}  // namespace pr::rt
