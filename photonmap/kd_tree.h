// KdTree: the photon map's search structure, Jensen's left-balanced implicit kd-tree. The
// photons themselves are the nodes, stored in heap order (node i has children 2i+1 and 2i+2,
// 0-based), so the tree costs no pointers and no memory beyond the photons (20 bytes each).
// Pass 1 builds one per map after the photon batches are merged; pass 2 (density_estimate.h)
// queries it from every PE as read-only replicated data. Jensen, "Realistic Image Synthesis
// Using Photon Mapping" (2001), ch. 6; seed chapter "Global Illumination in Complex Scenes
// using Photon Maps", section 2.3 (the maximum search radius).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "photonmap/photon.h"

namespace pr::par {
class Runtime;
}

namespace pr::pm {

// One photon found by a search: its index in KdTree::photons() and its squared distance.
struct Neighbor {
  float distSq = 0.0f;
  std::uint32_t index = 0;
};

// The result of a k-nearest search, reused from query to query (no allocation once warm).
// neighbors is a max-heap on distSq (the farthest first) until sortByDistance() is called.
// radiusSq is the squared radius of the disc the search covered: the distance of the k-th
// photon when k were found, the maximum radius squared when fewer were (Jensen: the count of
// a sparse region is the count in the whole search sphere), 0 for k = 0 or a radius <= 0.
struct NearestPhotons {
  std::vector<Neighbor> neighbors;
  float radiusSq = 0.0f;

  std::size_t size() const { return neighbors.size(); }
  bool empty() const { return neighbors.empty(); }
  void sortByDistance() {
    std::sort(neighbors.begin(), neighbors.end(), [](const Neighbor& a, const Neighbor& b) {
      return a.distSq < b.distSq || (a.distSq == b.distSq && a.index < b.index);
    });
  }
};

struct AcceptAll {
  bool operator()(const Photon&) const { return true; }
};

class KdTree {
 public:
  KdTree() = default;

  // Balances photons (any order) into heap order: each node is the median of its subtree
  // along the largest extent of the subtree's photons, and the median is placed so that the
  // tree is left-balanced (every level full but the last, which fills from the left) — the
  // heap holds exactly size() photons, none lost or duplicated. Serial, on the calling thread.
  static KdTree build(std::vector<Photon> photons);
  // The same tree bit for bit, built on the runtime: the top levels are split on the calling
  // thread, then each subtree below them is one task of stage "photon-kd-build" (demand-driven
  // by the runtime's schedule). Called by the controlling thread between stages.
  static KdTree build(std::vector<Photon> photons, par::Runtime& runtime);

  std::size_t size() const { return nodes_.size(); }
  bool empty() const { return nodes_.empty(); }
  std::span<const Photon> photons() const { return nodes_; }
  std::size_t bytes() const { return nodes_.size() * sizeof(Photon); }

  // The up to k photons nearest to x within maxRadius (distance <= maxRadius) that accept
  // takes (accept(const Photon&) -> bool; asked only about photons inside the current search
  // sphere, so it may be costly). Ties at the k-th distance are broken by traversal order.
  // k <= 0, an empty tree or maxRadius < 0 (or NaN) find nothing. Thread-safe (const).
  template <class Accept>
  void nearest(const glm::vec3& x, int k, float maxRadius, Accept&& accept, NearestPhotons& out) const;
  void nearest(const glm::vec3& x, int k, float maxRadius, NearestPhotons& out) const {
    nearest(x, k, maxRadius, AcceptAll{}, out);
  }

  // Calls fn(index, distSq) for every photon with distance <= radius (range search).
  template <class Fn>
  void forEachWithin(const glm::vec3& x, float radius, Fn&& fn) const;
  std::size_t countWithin(const glm::vec3& x, float radius) const {
    std::size_t n = 0;
    forEachWithin(x, radius, [&](std::uint32_t, float) { ++n; });
    return n;
  }

 private:
  // The traversal both searches share; see its definition below.
  template <class Visit, class Bound>
  void walk(const glm::vec3& x, Visit&& visit, Bound&& bound) const;

  std::vector<Photon> nodes_;  // heap order
};

// ---- search (templates) ---------------------------------------------------------------------

namespace detail {
inline float distSq(const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 d = a - b;
  return d.x * d.x + d.y * d.y + d.z * d.z;
}
// A subtree still to visit: its root and the squared distance from x to its splitting plane
// (a lower bound on the distance to every photon in it). One per level at most.
struct PendingSubtree {
  std::uint32_t node;
  float planeDistSq;
};
inline constexpr int kMaxDepth = 64;
}  // namespace detail

// Jensen's locate_photons, iterative, for both searches: visit a node (visit(index, photon,
// squared distance to x)), push its far child with the squared distance to its splitting plane
// (a lower bound for every photon in it), descend to the near child; pop a far child only while
// its plane is still inside the search sphere, whose squared radius bound() may shrink as
// visit() finds photons. At most one pending subtree per level.
template <class Visit, class Bound>
void KdTree::walk(const glm::vec3& x, Visit&& visit, Bound&& bound) const {
  if (nodes_.empty()) return;
  const auto n = static_cast<std::uint32_t>(nodes_.size());
  detail::PendingSubtree stack[detail::kMaxDepth];
  int top = 0;
  std::uint32_t i = 0;
  for (;;) {
    const Photon& p = nodes_[i];
    visit(i, p, detail::distSq(p.position, x));
    const std::uint32_t left = 2 * i + 1;
    if (left < n) {
      const int axis = p.splitAxis();
      const float d = x[axis] - p.position[axis];
      const std::uint32_t near = d < 0.0f ? left : left + 1;
      const std::uint32_t far = d < 0.0f ? left + 1 : left;
      if (far < n) stack[top++] = {far, d * d};
      if (near < n) {
        i = near;
        continue;
      }
    }
    for (;;) {
      if (top == 0) return;
      const detail::PendingSubtree& s = stack[--top];
      if (s.planeDistSq < bound()) {
        i = s.node;
        break;
      }
    }
  }
}

// The k nearest: until k photons are found the sphere is the maximum radius (inclusive: the
// bound is the next float above maxRadius^2, compared with <); from then on it is the k-th
// distance, so only strictly nearer photons replace the farthest.
template <class Accept>
void KdTree::nearest(const glm::vec3& x, int k, float maxRadius, Accept&& accept, NearestPhotons& out) const {
  out.neighbors.clear();
  out.radiusSq = 0.0f;
  if (k <= 0 || !(maxRadius >= 0.0f)) return;
  const float maxSq = maxRadius * maxRadius;
  out.radiusSq = maxSq;
  if (nodes_.empty()) return;
  const auto capacity = static_cast<std::size_t>(k);
  out.neighbors.reserve(std::min(capacity, nodes_.size()));
  float bound = std::nextafter(maxSq, std::numeric_limits<float>::infinity());
  auto farther = [](const Neighbor& a, const Neighbor& b) { return a.distSq < b.distSq; };
  walk(
      x,
      [&](std::uint32_t i, const Photon& p, float d2) {
        if (!(d2 < bound) || !accept(p)) return;
        if (out.neighbors.size() < capacity) {
          out.neighbors.push_back({d2, i});
          if (out.neighbors.size() == capacity) {
            std::make_heap(out.neighbors.begin(), out.neighbors.end(), farther);
            bound = out.neighbors.front().distSq;
          }
        } else {
          std::pop_heap(out.neighbors.begin(), out.neighbors.end(), farther);
          out.neighbors.back() = {d2, i};
          std::push_heap(out.neighbors.begin(), out.neighbors.end(), farther);
          bound = out.neighbors.front().distSq;
        }
      },
      [&] { return bound; });
  if (out.neighbors.size() == capacity) out.radiusSq = bound;
  else if (out.neighbors.size() > 1) std::make_heap(out.neighbors.begin(), out.neighbors.end(), farther);
}

template <class Fn>
void KdTree::forEachWithin(const glm::vec3& x, float radius, Fn&& fn) const {
  if (!(radius >= 0.0f)) return;
  const float bound = std::nextafter(radius * radius, std::numeric_limits<float>::infinity());
  walk(
      x, [&](std::uint32_t i, const Photon&, float d2) {
        if (d2 < bound) fn(i, d2);
      },
      [&] { return bound; });
}

}  // namespace pr::pm
