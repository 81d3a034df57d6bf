// Balancing of the left-balanced kd-tree (kd_tree.h): median splits along the largest extent,
// the median's rank chosen so the heap fills level by level from the left. Jensen's published
// balancing code is known to lose a few photons; here the rank is the size of a complete
// tree's left subtree (leftSubtreeSize), every photon lands in exactly one heap slot, and
// tests/photonmap/kd_tree_test.cpp finds every photon again by search.
#include "photonmap/kd_tree.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "common/parallel/runtime.h"
#include "common/util/error.h"

namespace pr::pm {

namespace {

// Photons in the left subtree of a left-balanced tree of m nodes: the full levels above the
// last contribute 2^(h-1) - 1 of their 2^h - 1, the last level (m - (2^h - 1) nodes, filled
// from the left) gives the left subtree up to its 2^(h-1) slots.
std::size_t leftSubtreeSize(std::size_t m) {
  if (m <= 1) return 0;
  const int h = std::bit_width(m) - 1;  // levels 0..h, level h possibly partial
  const std::size_t halfLast = std::size_t{1} << (h - 1);
  const std::size_t last = m - ((std::size_t{1} << h) - 1);
  return (halfLast - 1) + std::min(last, halfLast);
}

int largestExtentAxis(const Photon* begin, const Photon* end) {
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (const Photon* p = begin; p != end; ++p) {
    lo = glm::min(lo, p->position);
    hi = glm::max(hi, p->position);
  }
  const glm::vec3 extent = hi - lo;
  // Ties go to the lower axis, so the choice depends on the photons only.
  if (extent.x >= extent.y && extent.x >= extent.z) return 0;
  return extent.y >= extent.z ? 1 : 2;
}

// Splits photons[begin, end) (the subtree rooted at heap slot `node`): the median goes to
// heap[node], the photons below it to [begin, begin + L), those above to the rest.
void splitOne(std::vector<Photon>& work, std::size_t begin, std::size_t end, std::vector<Photon>& heap,
              std::size_t node, std::size_t& leftEnd) {
  const std::size_t m = end - begin;
  const std::size_t left = leftSubtreeSize(m);
  Photon* first = work.data() + begin;
  Photon* last = work.data() + end;
  const int axis = m > 1 ? largestExtentAxis(first, last) : 0;
  if (m > 1) {
    std::nth_element(first, first + left, last, [axis](const Photon& a, const Photon& b) {
      return a.position[axis] < b.position[axis];
    });
  }
  Photon median = first[left];
  median.setSplitAxis(axis);
  heap[node] = median;
  leftEnd = begin + left;
}

// Balances the whole subtree (serial recursion; depth is log2 of its size).
void balance(std::vector<Photon>& work, std::size_t begin, std::size_t end, std::vector<Photon>& heap,
             std::size_t node) {
  while (end > begin) {
    std::size_t mid = 0;
    splitOne(work, begin, end, heap, node, mid);
    balance(work, begin, mid, heap, 2 * node + 1);
    begin = mid + 1;  // the right subtree, iteratively
    node = 2 * node + 2;
  }
}

// A subtree left for a task: photons [begin, end) of the work array, rooted at heap slot node.
struct Subtree {
  std::size_t begin, end, node;
};

// Splits the top `levels` levels on the calling thread and returns the subtrees below them in
// heap order (left to right), the tasks of the parallel build.
std::vector<Subtree> splitTop(std::vector<Photon>& work, std::vector<Photon>& heap, int levels) {
  std::vector<Subtree> frontier{{0, work.size(), 0}};
  for (int l = 0; l < levels; ++l) {
    std::vector<Subtree> next;
    for (const Subtree& s : frontier) {
      if (s.end == s.begin) continue;
      std::size_t mid = 0;
      splitOne(work, s.begin, s.end, heap, s.node, mid);
      next.push_back({s.begin, mid, 2 * s.node + 1});
      next.push_back({mid + 1, s.end, 2 * s.node + 2});
    }
    frontier = std::move(next);
  }
  return frontier;
}

void checkSize(std::size_t n) {
  // Node indices are 32-bit in the search (2i + 2 must not overflow).
  PR_CHECK(n < (std::size_t{1} << 31), "KdTree: " + std::to_string(n) + " photons, at most 2^31 - 1");
}

}  // namespace

KdTree KdTree::build(std::vector<Photon> photons) {
  checkSize(photons.size());
  KdTree tree;
  tree.nodes_.resize(photons.size());
  balance(photons, 0, photons.size(), tree.nodes_, 0);
  return tree;
}

KdTree KdTree::build(std::vector<Photon> photons, par::Runtime& runtime) {
  checkSize(photons.size());
  // Below this size a subtree costs less than a stage's wake-up and barrier (~20 us at P = 2,
  // README, bench_runtime): one thread builds it.
  constexpr std::size_t kMinParallelPhotons = std::size_t{1} << 15;
  if (runtime.pes() == 1 || photons.size() < kMinParallelPhotons) return build(std::move(photons));
  const int local = runtime.localPes();
  // Every PE holds the photons (gathered to all, booked as their broadcast), so every rank
  // builds the same tree, a replicated computation, bit for bit alike: its top levels on the
  // controlling thread, the subtrees below them by the rank's PEs, each writing disjoint ranges
  // of the rank's arrays. A subtree's task is pinned to a PE of the rank that holds it (with
  // about 4 per PE, round robin evens out left-balanced subtrees, which differ in size by at
  // most a factor of 2); the rank's tasks follow every other rank's in the stage.
  KdTree tree;
  tree.nodes_.resize(photons.size());
  const int levels = std::bit_width(static_cast<unsigned>(4 * local) - 1);
  const std::vector<Subtree> subtrees = splitTop(photons, tree.nodes_, levels);
  par::TaskSet tasks;
  std::vector<int> owner;
  for (int r = 0; r < runtime.ranks(); ++r)
    for (std::size_t i = 0; i < subtrees.size(); ++i) {
      tasks.tasks.push_back({static_cast<double>(subtrees[i].end - subtrees[i].begin), static_cast<float>(i), float(r)});
      owner.push_back(r * local + int(i) % local);
    }
  runtime.runPinned("photon-kd-build", tasks, std::move(owner), [&](par::Pe&, par::TaskId t) {
    const Subtree& s = subtrees[static_cast<std::size_t>(t) % subtrees.size()];
    balance(photons, s.begin, s.end, tree.nodes_, s.node);  // disjoint ranges of both arrays
  });
  return tree;
}

}  // namespace pr::pm
