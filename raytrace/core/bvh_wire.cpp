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
  return bvh;
}

}  // namespace pr::rt
