// OwnerDirectory: the replicated top-level structure of object partitioning, a bounding volume
// hierarchy over the owners' bounds (each the union of its pieces' grown bounds,
// object_assignment.h) that every PE keeps a copy of (counted in the broadcast). It answers
// which owners a ray can reach and from where, so the originator asks them nearest first and
// stops once its closest hit is nearer than the next owner's entry, instead of testing every
// piece and asking every owner it may reach at once.
#pragma once

#include <cstdint>
#include <vector>

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"
#include "raytrace/partition/object_assignment.h"

namespace pr::rt {

// An owner a ray reaches and where it enters the owner's bounds (conservative: no farther
// than any hit on the owner's triangles).
struct OwnerEntry {
  float t = 0.0f;
  int owner = 0;
};

class OwnerDirectory {
 public:
  OwnerDirectory() = default;
  explicit OwnerDirectory(const ObjectAssignment& assignment);

  // A node waiting in the walk's heap (the caller's storage, reused between rays).
  struct NodeEntry {
    float t = 0.0f;
    uint32_t node = 0;
  };
  // The owners other than `except` whose pieces the ray reaches for t in [tMin, tMax], each
  // once with its nearest entry, nearest first. A pure function of the ray and `except`.
  void ownersNearestFirst(const Ray& ray, int except, std::vector<OwnerEntry>& out, std::vector<NodeEntry>& heap) const;
  // Bytes every PE holds a copy of: the tree's nodes.
  size_t bytes() const { return nodes_.size() * sizeof(Node); }

 private:
  struct Node {
    // The box as 4 lanes for the SSE slab test; lane 3 is (-inf, +inf), which never limits.
    alignas(16) float lo[4];
    alignas(16) float hi[4];
    uint32_t first = 0;  // a leaf: index into leaves_; else the first of two child nodes
    bool leaf = false;
  };
  struct Leaf {
    scene::Bounds box;  // the owner's pieces' bounds, grown by the margin
    int owner = 0;
  };
  void build(uint32_t node, uint32_t begin, uint32_t end);

  std::vector<Node> nodes_;
  std::vector<Leaf> leaves_;      // one per owner that holds pieces, in tree order
  std::vector<bool> ownsPieces_;  // per PE
};

}  // namespace pr::rt
