// VoxelSplit: the object-space partitioning of the scene (seed section 5.1.2): its space cut
// by a kd split into P or k·P voxels balanced by estimated cost (work where the camera rays
// land, or triangle count per side; not equal sizes), each voxel holding the triangles that
// overlap it. object_space.cpp gives each
// voxel an owner PE, builds that PE's BVHs over its voxels only, and moves rays from owner to
// owner in the order walk() visits the voxels along them.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "common/parallel/wire.h"
#include "common/scene/scene.h"
#include "raytrace/core/ray.h"
#include "raytrace/partition/ray_slabs.h"
#include "raytrace/partition/view_work.h"

namespace pr::rt {

struct VoxelSplitOptions {
  int voxels = 1;  // leaves of the kd split: P, or k·P for finer ownership (1..4096)
  // A voxel's geometry is every triangle whose bounds overlap the voxel grown by this much on
  // every side (partitionMargin, partition_margin.h): conservative, so a hit computed at a ray
  // parameter inside a voxel's span is always on a triangle that voxel holds.
  float margin = 0.0f;
  // Where the render's work lies (view_work.h; any unit): when given (and not all zero), each
  // cut puts on each side work in proportion to the voxels it will become, on the axis that
  // balances it best and duplicates the fewest triangles; else triangle counts are balanced.
  std::span<const WorkPoint> work{};
  // Triangles every PE holds a copy of (scene indices): left out of the held-only content
  // boxes (reachesHeldOnly).
  std::span<const uint32_t> replicated{};
};

// The part of a ray inside one voxel: t in [tEnter, tExit]. Consecutive spans of a walk share
// their boundary value exactly (the same float), so the spans of a ray cover [tMin, tMax]
// without gaps or overlaps.
struct VoxelSpan {
  uint32_t voxel = 0;
  float tEnter = 0.0f, tExit = 0.0f;
};

class VoxelSplit {
 public:
  // The kd tree has at most this depth; walk() keeps its stack on the call stack.
  static constexpr int kMaxDepth = 48;

  VoxelSplit() = default;
  // Throws pr::InputError for a voxel count outside [1, 4096].
  VoxelSplit(const scene::Scene& scene, const VoxelSplitOptions& options);

  int voxels() const { return static_cast<int>(cells_.size()); }
  float margin() const { return margin_; }
  // The voxel's region. The kd root is all of space, so faces on the outside are at +-infinity:
  // a hit computed a little outside the scene bounds still lies in some voxel.
  const scene::Bounds& cell(int voxel) const { return cells_[voxel]; }
  // Scene triangle indices of the voxel's geometry, ascending.
  std::span<const uint32_t> triangles(int voxel) const { return triangles_[voxel]; }
  // The voxel containing p; a point on a split plane belongs to the upper side.
  int voxelAt(glm::vec3 p) const;
  // Total triangles over all voxels (> the scene's when triangles straddle splits).
  size_t storedTriangles() const;
  // The estimated work in the voxel: the weight of the work points inside its cell (0 for
  // every voxel of a split made without work points).
  double work(int voxel) const { return work_.empty() ? 0.0 : work_[size_t(voxel)]; }
  bool hasWork() const { return !work_.empty(); }
  // Bytes of the kd tree and the voxels' content boxes, which every PE keeps a copy of to
  // route rays.
  size_t treeBytes() const { return nodes_.size() * sizeof(Node) + (content_.size() + heldOnly_.size()) * sizeof(SlabBoxes4); }

  // What a voxel holds, as up to kContentBoxes boxes inside its cell: per scene object the
  // bounds of its triangles' parts in the cell, the largest (by surface area) kept apart and
  // the rest merged, all grown by the margin, in groups of four tested together. False when
  // the ray (slabs) touches none of them for t in [t0, t1] (always for a voxel without
  // triangles, which has none): then no triangle of the voxel has a hit in that span, and a
  // ray that crosses the voxel through empty space need not visit its owner. Conservative.
  static constexpr int kContentBoxes = 8;
  bool reachesContent(uint32_t voxel, const RaySlabs& slabs, float t0, float t1) const {
    return reaches(content_, contentFirst_, voxel, slabs, t0, t1);
  }
  // The same for the voxel's triangles other than the options' replicated ones, which only
  // its owner holds: false when no such triangle has a hit in [t0, t1].
  bool reachesHeldOnly(uint32_t voxel, const RaySlabs& slabs, float t0, float t1) const {
    return heldOnlyFirst_.empty() ? reachesContent(voxel, slabs, t0, t1) : reaches(heldOnly_, heldOnlyFirst_, voxel, slabs, t0, t1);
  }

  // Calls visit(const VoxelSpan&) for each voxel the ray passes through for t in
  // [tMin, tMax], nearest first, until visit returns false. A ray lying in a split plane
  // belongs to the upper side; a ray whose origin is on a plane goes to the side it points to.
  // Pure function of the ray: every PE walking the same ray gets the same spans.
  template <class Visit>
  void walk(const Ray& ray, Visit&& visit) const;
  std::vector<VoxelSpan> spans(const Ray& ray) const;

  // The whole split as bytes (voxel_split_wire.cpp), and back: a rank that decodes it walks
  // rays through the same voxels and finds the same triangles in each as the rank that made it.
  // decode throws par::WireError for bytes that are not an encoding.
  void encode(par::WireWriter& w) const;
  static VoxelSplit decode(par::WireReader& r);

 private:
  // axis < 0: a leaf, voxel index in `left`. Otherwise children `left` (below split) and
  // `right` (at or above split).
  struct Node {
    int axis = -1;
    float split = 0.0f;
    uint32_t left = 0, right = 0;
  };
  struct Built;

  uint32_t build(Built& b, const scene::Bounds& cell, std::vector<uint32_t> tris, std::vector<uint32_t> points, int leaves,
                 int depth);
  void buildContent(const scene::Scene& scene, const Built& b);
  static bool reaches(const std::vector<SlabBoxes4>& boxes, const std::vector<uint32_t>& first, uint32_t voxel,
                      const RaySlabs& slabs, float t0, float t1) {
    for (uint32_t i = first[voxel]; i < first[voxel + 1]; ++i)
      if (slabs.overlapsAny(boxes[i], t0, t1)) return true;
    return false;
  }

  std::vector<Node> nodes_;
  std::vector<scene::Bounds> cells_;
  std::vector<std::vector<uint32_t>> triangles_;
  std::vector<SlabBoxes4> content_;   // voxel v's groups: [contentFirst_[v], contentFirst_[v + 1])
  std::vector<uint32_t> contentFirst_;
  std::vector<SlabBoxes4> heldOnly_;  // the same without the replicated triangles; both
  std::vector<uint32_t> heldOnlyFirst_;  // empty when nothing is replicated
  std::vector<double> work_;  // per voxel, when built with work points
  float margin_ = 0.0f;
};

// Owners of k·P voxels: longest processing time first by estimated work (the voxel's work plus
// triangleWork per triangle it holds: the work of holding one, its share of the owner's BVH
// build, in the work points' unit, so a cluster of many triangles but little view work is not
// dealt to one PE whole), or by triangle count for a split made without work points (ties to
// the lower voxel, then the lower PE), so every PE gets about the same work (or geometry); with
// as many voxels as PEs, voxel i goes to PE i.
std::vector<int> assignVoxelOwners(const VoxelSplit& split, int pes, float triangleWork = 0.0f);

template <class Visit>
void VoxelSplit::walk(const Ray& ray, Visit&& visit) const {
  if (nodes_.empty()) return;
  struct Pending {
    uint32_t node;
    float t0, t1;
  };
  Pending stack[kMaxDepth];
  int top = 0;
  uint32_t node = 0;
  float t0 = ray.tMin, t1 = ray.tMax;
  if (!(t0 <= t1)) return;
  for (;;) {
    const Node& n = nodes_[node];
    if (n.axis < 0) {
      if (!visit(VoxelSpan{n.left, t0, t1})) return;
      if (top == 0) return;
      --top;
      node = stack[top].node;
      t0 = stack[top].t0;
      t1 = stack[top].t1;
      continue;
    }
    const float o = ray.origin[n.axis], d = ray.direction[n.axis];
    // The side the ray starts in; on the plane, the side it moves into (the upper one when it
    // moves along the plane, matching voxelAt and the closed overlap test of the geometry).
    const bool startsBelow = o < n.split || (o == n.split && d < 0.0f);
    const uint32_t first = startsBelow ? n.left : n.right;
    const uint32_t second = startsBelow ? n.right : n.left;
    if (d == 0.0f) {
      node = first;
      continue;
    }
    // One division per node, shared by both children, so their spans meet at the same float.
    const float tSplit = (n.split - o) / d;
    if (!(tSplit > 0.0f) || tSplit >= t1) {
      node = first;  // moves away from the plane, or reaches it only after t1
    } else if (tSplit <= t0) {
      node = second;  // crossed it before t0
    } else {
      stack[top++] = {second, tSplit, t1};
      node = first;
      t1 = tSplit;
    }
  }
}

}  // namespace pr::rt
