// The bounding volume hierarchy every ray tracer queries: built with the binned surface area
// heuristic over any subset of the scene's triangles (image-space: all of them; object-space
// and object partitioning: one PE's own triangles only), stored as 32-byte nodes in depth-first
// order with the leaf triangles copied next to it. Queries: closest hit and any hit (shadow).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "raytrace/core/ray.h"

namespace pr::rt {

// One node, 32 bytes (two per cache line). Interior: count == 0, the first child is the next
// node, `offset` the second. Leaf: triangles [offset, offset + count) of Bvh::triangles().
// `axis` is the split axis of an interior node (the build's choice, kept for inspection).
struct BvhNode {
  glm::vec3 boundsMin;
  uint32_t offset;
  glm::vec3 boundsMax;
  uint16_t count;
  uint8_t axis;
  uint8_t pad;

  bool isLeaf() const { return count > 0; }
};
static_assert(sizeof(BvhNode) == 32, "BvhNode must stay 32 bytes");

// A leaf triangle: its world-space vertices (copied so a leaf is one contiguous read) and its
// scene triangle index, which hit records report. 40 bytes.
struct BvhTriangle {
  glm::vec3 p0, p1, p2;
  uint32_t triangle;
};

struct BvhBuildOptions {
  int bins = 32;          // SAH bins per axis (Wald 2007, "On fast construction of SAH-based BVHs")
  int maxLeafSize = 4;    // a leaf never holds more triangles than this
  float traversalCost = 1.0f;     // SAH cost of visiting a node, relative to one triangle test
  float intersectionCost = 1.0f;  // SAH cost of one watertight triangle test
};

// Counts of one build, for benchmarks and reports (Category/what naming in the run record).
struct BvhStats {
  size_t nodes = 0;
  size_t leaves = 0;
  size_t triangles = 0;
  size_t degenerateTriangles = 0;  // stored, but made unhittable (see bvh_build.cpp)
  int maxDepth = 0;
  size_t memoryBytes = 0;          // nodes + leaf triangles
};

class Bvh {
 public:
  Bvh() = default;
  // All triangles of the scene.
  explicit Bvh(const scene::Scene& scene, const BvhBuildOptions& options = {});
  // Only the listed scene triangles (indices into triangles); hits report these indices.
  Bvh(std::span<const glm::vec3> positions, std::span<const scene::Triangle> triangles,
      std::span<const uint32_t> subset, const BvhBuildOptions& options = {});

  // Closest hit with t in [ray.tMin, ray.tMax]; equal t goes to the lower triangle index.
  // Returns false (and leaves `hit` untouched) when nothing is hit. Thread-safe (read-only).
  bool intersect(const Ray& ray, Hit& hit) const;
  // True when any triangle is hit with t in [ray.tMin, ray.tMax] (shadow rays); stops at the
  // first one found. Agrees with intersect(): occluded(r) == intersect(r, h).
  bool occluded(const Ray& ray) const;

  bool empty() const { return nodes_.empty(); }
  std::span<const BvhNode> nodes() const { return nodes_; }
  std::span<const BvhTriangle> triangles() const { return triangles_; }
  const BvhStats& stats() const { return stats_; }
  scene::Bounds bounds() const;

 private:
  void build(std::span<const glm::vec3> positions, std::span<const scene::Triangle> triangles,
             std::span<const uint32_t> subset, const BvhBuildOptions& options);
  template <int Kz> bool intersectK(const Ray& ray, Hit& hit) const;
  template <int Kz> bool occludedK(const Ray& ray) const;

  std::vector<BvhNode> nodes_;
  std::vector<BvhTriangle> triangles_;
  BvhStats stats_;
  float magnitude_ = 0.0f;  // largest |coordinate| of any vertex, for the traversal slack
};

}  // namespace pr::rt
