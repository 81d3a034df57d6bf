// The BVH's encoding (bvh.h): its root, bounds, slack magnitude and build figures, then its
// wide nodes and leaf blocks as they lie in memory (each a sequence: a count, then the
// elements). A rank that receives it traverses the same nodes as the rank that built it, so
// its hits, and the image, are the same bit for bit.
#include <type_traits>

#include "common/parallel/wire.h"
#include "raytrace/core/bvh.h"

namespace pr::rt {

static_assert(std::is_trivially_copyable_v<BvhNode> && std::is_trivially_copyable_v<BvhLeafBlock>);
static_assert(std::is_trivially_copyable_v<scene::Bounds> && std::is_trivially_copyable_v<BvhStats>);

std::size_t Bvh::encodedBytes() const {
  return sizeof root_ + sizeof bounds_ + sizeof magnitude_ + sizeof stats_ + 2 * sizeof(uint64_t) +
         nodes_.size() * sizeof(BvhNode) + leafBlocks_.size() * sizeof(BvhLeafBlock);
}

void Bvh::encode(par::WireWriter& w) const {
  w.reserve(encodedBytes());
  w.value(root_);
  w.value(bounds_);
  w.value(magnitude_);
  w.value(stats_);
  w.sequence(std::span<const BvhNode>(nodes_));
  w.sequence(std::span<const BvhLeafBlock>(leafBlocks_));
}

Bvh Bvh::decode(par::WireReader& r, std::shared_ptr<const AlphaTest> alpha) {
  Bvh bvh;
  bvh.root_ = r.value<uint32_t>();
  bvh.bounds_ = r.value<scene::Bounds>();
  bvh.magnitude_ = r.value<float>();
  bvh.stats_ = r.value<BvhStats>();
  bvh.nodes_ = r.sequence<BvhNode>();
  bvh.leafBlocks_ = r.sequence<BvhLeafBlock>();
  bvh.alpha_ = std::move(alpha);
  // What another rank sent is traversed as it is: every reference must name a leaf's blocks
  // inside the leaf array or a node after the one that names it (depth-first order, so no
  // cycle), or nothing. A reference that does not throws before any traversal reads it.
  const std::size_t nodes = bvh.nodes_.size(), blocks = bvh.leafBlocks_.size();
  const auto check = [&](uint32_t ref, std::size_t after) {
    if (ref == BvhRef::kEmpty) return;
    if (BvhRef::isLeaf(ref)) {
      if (std::size_t(BvhRef::leafFirst(ref)) + rt::leafBlocks(BvhRef::leafCount(ref)) > blocks)
        throw par::WireError("a BVH leaf beyond its leaf blocks");
    } else if (ref >= nodes || (after < nodes && ref <= after)) {
      throw par::WireError("a BVH node reference out of order or out of range");
    }
  };
  check(bvh.root_, nodes);
  for (std::size_t i = 0; i < nodes; ++i)
    for (uint32_t child : bvh.nodes_[i].child) check(child, i);
  return bvh;
}

}  // namespace pr::rt
