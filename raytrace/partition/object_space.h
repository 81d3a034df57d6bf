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
  // dealt evenly (4 is fastest on the hot-spot scene at P = 2 among 2, 4 and 8).
  explicit ObjectSpacePartition(int voxelsPerPe = 4);
  std::string_view name() const override { return "object-space"; }
  TraceResult render(const TraceJob& job, par::Runtime& rt) override;

 private:
  int voxelsPerPe_;
};

}  // namespace pr::rt
