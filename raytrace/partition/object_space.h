// Object-space partitioning (seed section 5.1.2): space is split into voxels (voxel_split.h),
// each owned by a PE that holds only its voxels' geometry, in one BVH; rays are Channel
// messages that travel from owner to owner in the order they pass the voxels, until they hit
// inside the owner's voxels being traversed or leave the scene. The owner of a hit shades and
// sends the rays it spawns on their way. Termination detection of the runtime ends the frame.
#pragma once

#include <memory>
#include <string_view>

#include "raytrace/partition/partition.h"
#include "raytrace/partition/partitioned.h"

namespace pr::rt {

class ObjectSpacePartition final : public Partition {
 public:
  // voxelsPerPe: k of the k·P voxels (1..64); more voxels than PEs let the owners' work be
  // dealt evenly, fewer mean shorter walks and fewer rays between owners. 2 is fastest on the
  // hot-spot scene at P = 2 among 1 to 4, and as fast as 4 on the landscape, since the owners
  // build their BVHs as the trace stage's set-up (with a build stage of its own, whose
  // barrier waited for the owner with the most triangles, 4 was).
  explicit ObjectSpacePartition(int voxelsPerPe = 2);
  std::string_view name() const override { return "object-space"; }
  // Rays travel between ranks as messages; rank 0 sends the split (object_space.cpp).
  bool runsAcrossRanks() const override { return true; }
  TraceResult render(const TraceJob& job, par::Runtime& rt) override;

 private:
  int voxelsPerPe_;
};

}  // namespace pr::rt
