// VoxelSplit: the object-space partitioning of the scene (seed section 5.1.2): its space cut
// by a kd split into P or k·P voxels balanced by estimated cost (triangle count per side, not
// equal sizes), each voxel holding the triangles that overlap it. object_space.cpp gives each
// voxel an owner PE, builds that PE's BVHs over its voxels only, and moves rays from owner to
// owner in the order walk() visits the voxels along them.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"

namespace pr::rt {

struct VoxelSplitOptions {
  int voxels = 1;  // leaves of the kd split: P, or k·P for finer ownership (1..4096)
  // A voxel's geometry is every triangle whose bounds overlap the voxel grown by this much on
  // every side (partitionMargin, partition_margin.h): conservative, so a hit computed at a ray
  // parameter inside a voxel's span is always on a triangle that voxel holds.
  float margin = 0.0f;
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
  // Bytes of the kd tree itself, which every PE keeps a copy of to route rays.
  size_t treeBytes() const { return nodes_.size() * sizeof(Node); }

  // Calls visit(const VoxelSpan&) for each voxel the ray passes through for t in
  // [tMin, tMax], nearest first, until visit returns false. A ray lying in a split plane
  // belongs to the upper side; a ray whose origin is on a plane goes to the side it points to.
  // Pure function of the ray: every PE walking the same ray gets the same spans.
  template <class Visit>
  void walk(const Ray& ray, Visit&& visit) const;
  std::vector<VoxelSpan> spans(const Ray& ray) const;

 private:
  // axis < 0: a leaf, voxel index in `left`. Otherwise children `left` (below split) and
  // `right` (at or above split).
  struct Node {
    int axis = -1;
    float split = 0.0f;
    uint32_t left = 0, right = 0;
  };
  struct Built;

  uint32_t build(Built& b, const scene::Bounds& cell, std::vector<uint32_t> tris, int leaves, int depth);

  std::vector<Node> nodes_;
  std::vector<scene::Bounds> cells_;
  std::vector<std::vector<uint32_t>> triangles_;
  float margin_ = 0.0f;
};

// Owners of k·P voxels: longest processing time first by triangle count (ties to the lower
// voxel, then the lower PE), so every PE holds about the same geometry; with as many voxels
// as PEs, voxel i goes to PE i.
std::vector<int> assignVoxelOwners(const VoxelSplit& split, int pes);

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
