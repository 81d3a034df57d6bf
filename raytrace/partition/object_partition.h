// Object partitioning (seed section 5.1.2): scene objects (glTF mesh primitives, split when
// large) are assigned to PEs balanced by triangle count (object_assignment.h); each PE holds
// only its objects' geometry and BVH. A ray's originator sends a query to every owner whose
// object bounds the ray can reach; each owner answers with its nearest hit; the originator
// keeps the closest (Hit::closerThan) and continues: shades, and becomes the originator of
// the rays it spawns. A shadow ray is blocked when any owner reports an occluder. The few
// small pieces rays reach most (a floor, a wall) are replicated on every PE, which answers for
// them itself.
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include "raytrace/partition/partition.h"
#include "raytrace/partition/partitioned.h"

namespace pr::rt {

// The share of the scene's triangles replicated on every PE (ObjectAssignmentOptions).
inline constexpr double kReplicatedFraction = 0.01;

class ObjectPartition final : public Partition {
 public:
  // maxPieceTriangles: objects above this are split (0: ObjectAssignmentOptions' default);
  // replicatedFraction: the budget of replicated pieces (0: none).
  explicit ObjectPartition(uint32_t maxPieceTriangles = 0, double replicatedFraction = kReplicatedFraction)
      : maxPieceTriangles_(maxPieceTriangles), replicatedFraction_(replicatedFraction) {}
  std::string_view name() const override { return "object"; }
  // Queries and hit replies travel between ranks; rank 0 sends the assignment (object_partition.cpp).
  bool runsAcrossRanks() const override { return true; }
  TraceResult render(const TraceJob& job, par::Runtime& rt) override;

 private:
  uint32_t maxPieceTriangles_;
  double replicatedFraction_;
};

}  // namespace pr::rt
