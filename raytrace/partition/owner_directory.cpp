// The owner directory's build (median split of the owners' box centres, one owner per leaf)
// and query (the owners a ray reaches, nearest first).
#include "raytrace/partition/owner_directory.h"

#include <algorithm>
#include <cmath>


namespace pr::rt {


OwnerDirectory::OwnerDirectory(const ObjectAssignment& assignment) {
  std::vector<scene::Bounds> ownerBounds(size_t(assignment.pes()));
  scene::Bounds replicated;  // listed as one more owner, kEveryPe
  for (const ObjectPiece& p : assignment.pieces())
    if (!p.bounds.empty()) (p.owner == kEveryPe ? replicated : ownerBounds[size_t(p.owner)]).extend(p.bounds);
  init(ownerBounds, assignment.margin(), replicated);
}

OwnerDirectory::OwnerDirectory(std::span<const scene::Bounds> boxes, float margin) { init(boxes, margin, {}); }

void OwnerDirectory::init(std::span<const scene::Bounds> boxes, float margin, const scene::Bounds& everyPe) {
  auto add = [&](scene::Bounds grown, int owner) {
    if (grown.empty()) return;
    grown.min -= glm::vec3(margin);
    grown.max += glm::vec3(margin);
    leaves_.push_back({grown, owner});
  };
  for (size_t o = 0; o < boxes.size(); ++o) add(boxes[o], int(o));
  add(everyPe, kEveryPe);
  if (leaves_.empty()) return;
  nodes_.reserve(2 * leaves_.size());
  nodes_.emplace_back();
  build(0, 0, uint32_t(leaves_.size()));
}

// Median split of the owners' box centres on their longest axis, one owner per leaf.
void OwnerDirectory::build(uint32_t node, uint32_t begin, uint32_t end) {
  scene::Bounds box, centres;
  for (uint32_t i = begin; i < end; ++i) {
    box.extend(leaves_[i].box);
    centres.extend(leaves_[i].box.center());
  }
  Node& n = nodes_[node];
  n.box = SlabBox::of(box);
  if (end - begin == 1) {
    n.leaf = true;
    n.first = begin;
    return;
  }
  const glm::vec3 extent = centres.max - centres.min;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(leaves_.begin() + begin, leaves_.begin() + mid, leaves_.begin() + end, [&](const Leaf& x, const Leaf& y) {
    const float cx = x.box.center()[axis], cy = y.box.center()[axis];
    return cx < cy || (cx == cy && x.owner < y.owner);
  });
  const auto left = uint32_t(nodes_.size());
  n.first = left;
  nodes_.emplace_back();  // invalidates n
  nodes_.emplace_back();
  build(left, begin, mid);
  build(left + 1, mid, end);
}

// Nodes in order of their entry (a heap): a node's entry is no farther than its children's,
// so owners come out nearest first.
OwnerDirectory::NearestFirst::NearestFirst(const OwnerDirectory& directory, const Ray& ray, int except,
                                           std::vector<NodeEntry>& heap, bool resume)
    : directory_(directory), slabs_(ray), except_(except), heap_(heap) {
  if (resume) return;
  heap_.clear();
  if (!directory_.nodes_.empty()) push(0);
}

void OwnerDirectory::NearestFirst::push(uint32_t node) {
  const Node& n = directory_.nodes_[node];
  if (n.leaf && directory_.leaves_[n.first].owner == except_) return;
  float entry;
  if (!slabs_.entry(n.box, entry)) return;
  heap_.push_back({entry, node});
  std::push_heap(heap_.begin(), heap_.end(), later);
}

bool OwnerDirectory::NearestFirst::next(float maxT, OwnerEntry& out) {
  while (!heap_.empty() && heap_.front().t <= maxT) {
    std::pop_heap(heap_.begin(), heap_.end(), later);
    const NodeEntry e = heap_.back();
    heap_.pop_back();
    const Node& n = directory_.nodes_[e.node];
    if (n.leaf) {
      out = {e.t, directory_.leaves_[n.first].owner};
      return true;
    }
    push(n.first);
    push(n.first + 1);
  }
  return false;
}

void OwnerDirectory::ownersNearestFirst(const Ray& ray, int except, std::vector<OwnerEntry>& out,
                                        std::vector<NodeEntry>& heap) const {
  out.clear();
  // A few owners: one box test each and a sort of what is reached costs less than the walk's
  // inner boxes and heap (at P = 2 the walk was a tenth of object partitioning's trace time).
  if (leaves_.size() <= kScannedOwners) {
    const RaySlabs slabs(ray);
    for (const Node& n : nodes_) {
      float t;
      if (n.leaf && leaves_[n.first].owner != except && slabs.entry(n.box, t)) out.push_back({t, leaves_[n.first].owner});
    }
    std::sort(out.begin(), out.end(), [](const OwnerEntry& x, const OwnerEntry& y) { return x.t < y.t || (x.t == y.t && x.owner < y.owner); });
    return;
  }
  NearestFirst walk(*this, ray, except, heap);
  OwnerEntry e;
  while (walk.next(kInfinity, e)) out.push_back(e);
}

}  // namespace pr::rt
