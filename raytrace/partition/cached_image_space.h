// Image-space partitioning with data management (seed chapter 4): image tiles are demand-driven
// tasks as in image-space, but the scene is not replicated. Its geometry is split into data
// items (the object pieces of object_assignment.h, each with its own BVH and vertex data) owned
// by PEs in compact Morton-curve runs; a PE tracing a ray walks a replicated directory of the
// items' bounds nearest first and takes each item it needs from its own partition, from its
// cache, or from the owner through the DataManager (a request and a reply message, served by
// the owner's PE), keeping fetched items in an LRU cache of --cache-mb. Before a tile it
// prefetches (--prefetch) what its profile predicts: the items its own finished neighbouring
// tiles used (seed section 4.5.3), or the items the tile's camera rays reach first; schedules
// that need cost estimates get them from a profile pre-pass. A ray that needs an item on its way
// is parked and the PE goes on with the tile's other rays (latency hiding, seed section 4.5.2;
// --no-latency-hiding waits instead); --data-latency-us simulates a network's latency. Run record: cache hits, misses and
// prefetches per PE (PeStageRecord), the fetched bytes as "data" traffic, the time spent
// waiting for items as message waiting, and Cache/... counters (a miss is one request; a use
// that finds its item already requested counts as Cache/misses_joined; prefetches, those
// predicted by the profile, and those the tile then used).
#pragma once

#include <cstddef>
#include <string_view>

#include "raytrace/partition/partition.h"

namespace pr::rt {

class CachedImageSpacePartition final : public Partition {
 public:
  std::string_view name() const override { return "image-space-cached"; }
  bool runsAcrossRanks() const override { return true; }
  TraceResult render(const TraceJob& job, par::Runtime& rt) override;
};

}  // namespace pr::rt
