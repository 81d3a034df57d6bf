// OwnerDirectory: the replicated top-level structure of object partitioning, a bounding volume
// hierarchy over the owners' bounds (each the union of its pieces' grown bounds,
// object_assignment.h) that every PE keeps a copy of (counted in the broadcast). It answers
// which owners a ray can reach and from where, so the originator asks them nearest first and
// stops once its closest hit is nearer than the next owner's entry, instead of testing every
// piece and asking every owner it may reach at once.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/ray_slabs.h"

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
  // Over the owners of the assignment's pieces, each with the union of its pieces' bounds; the
  // replicated pieces are one more owner, kEveryPe, which every PE answers for itself.
  explicit OwnerDirectory(const ObjectAssignment& assignment);
  // Over any boxes, grown by margin: entry i is box i (an empty box is never reached); the
  // "owners" it lists are box indices (the data items of image-space-cached).
  OwnerDirectory(std::span<const scene::Bounds> boxes, float margin);

  // A node waiting in the walk's heap (the caller's storage, reused between rays).
  struct NodeEntry {
    float t = 0.0f;
    uint32_t node = 0;
  };
  // The owners other than `except` whose pieces the ray reaches for t in [tMin, tMax], each
  // once with its nearest entry, nearest first (equal entries: the lower owner first, up to
  // kScannedOwners owners, which are tested one by one; the tree's order beyond). A pure
  // function of the ray and `except`.
  static constexpr size_t kScannedOwners = 8;
  void ownersNearestFirst(const Ray& ray, int except, std::vector<OwnerEntry>& out, std::vector<NodeEntry>& heap) const;
  // The owners a ray reaches, one at a time, nearest first, walking only as far as asked: the
  // cheap form when the search stops at the closest hit.
  class NearestFirst {
   public:
    // resume: continue a walk of the same ray whose state is `heap` (a walk parked midway).
    NearestFirst(const OwnerDirectory& directory, const Ray& ray, int except, std::vector<NodeEntry>& heap,
                 bool resume = false);
    // The next owner whose entry is no farther than maxT; false when there is none.
    bool next(float maxT, OwnerEntry& out);

   private:
    static bool later(const NodeEntry& a, const NodeEntry& b) { return a.t > b.t || (a.t == b.t && a.node > b.node); }
    void push(uint32_t node);
    const OwnerDirectory& directory_;
    RaySlabs slabs_;
    int except_;
    std::vector<NodeEntry>& heap_;
  };

  // Bytes every PE holds a copy of: the tree's nodes.
  size_t bytes() const { return nodes_.size() * sizeof(Node); }

 private:
  struct Node {
    SlabBox box;
    uint32_t first = 0;  // a leaf: index into leaves_; else the first of two child nodes
    bool leaf = false;
  };
  struct Leaf {
    scene::Bounds box;  // the owner's pieces' bounds, grown by the margin
    int owner = 0;
  };
  void init(std::span<const scene::Bounds> boxes, float margin, const scene::Bounds& everyPe);
  void build(uint32_t node, uint32_t begin, uint32_t end);

  std::vector<Node> nodes_;
  std::vector<Leaf> leaves_;      // one per owner that holds pieces, in tree order
};

}  // namespace pr::rt
