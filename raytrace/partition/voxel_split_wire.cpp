// The voxel split's encoding (voxel_split.h): its margin, kd nodes, cells, each voxel's
// triangle list, the content boxes with their per-voxel ranges (all of them, then those of
// the triangles only the owner holds) and the work per voxel, each a sequence as it lies in
// memory. Rank 0 makes the split once and sends it; every rank routes rays by the same tree.
#include <type_traits>

#include "raytrace/partition/voxel_split.h"

namespace pr::rt {

static_assert(std::is_trivially_copyable_v<SlabBoxes4> && std::is_trivially_copyable_v<scene::Bounds>);

void VoxelSplit::encode(par::WireWriter& w) const {
  static_assert(std::is_trivially_copyable_v<Node>);
  w.value(margin_);
  w.sequence(std::span<const Node>(nodes_));
  w.sequence(std::span<const scene::Bounds>(cells_));
  w.value(std::uint64_t(triangles_.size()));
  for (const std::vector<uint32_t>& t : triangles_) w.sequence(std::span<const uint32_t>(t));
  w.sequence(std::span<const SlabBoxes4>(content_));
  w.sequence(std::span<const uint32_t>(contentFirst_));
  w.sequence(std::span<const SlabBoxes4>(heldOnly_));
  w.sequence(std::span<const uint32_t>(heldOnlyFirst_));
  w.sequence(std::span<const double>(work_));
}

VoxelSplit VoxelSplit::decode(par::WireReader& r) {
  VoxelSplit s;
  s.margin_ = r.value<float>();
  s.nodes_ = r.sequence<Node>();
  s.cells_ = r.sequence<scene::Bounds>();
  const auto voxels = r.value<std::uint64_t>();
  if (voxels != s.cells_.size()) throw par::WireError("a voxel split whose triangle lists do not match its voxels");
  s.triangles_.resize(static_cast<std::size_t>(voxels));
  for (std::vector<uint32_t>& t : s.triangles_) t = r.sequence<uint32_t>();
  s.content_ = r.sequence<SlabBoxes4>();
  s.contentFirst_ = r.sequence<uint32_t>();
  s.heldOnly_ = r.sequence<SlabBoxes4>();
  s.heldOnlyFirst_ = r.sequence<uint32_t>();
  s.work_ = r.sequence<double>();
  // The walk and the content tests index by these; a short table would read past its end.
  const auto ranges = [&](const std::vector<uint32_t>& first, std::size_t boxes) {
    if (first.size() != s.cells_.size() + 1 || first.back() > boxes)
      throw par::WireError("a voxel split whose content boxes do not match its voxels");
  };
  ranges(s.contentFirst_, s.content_.size());
  if (!s.heldOnlyFirst_.empty()) ranges(s.heldOnlyFirst_, s.heldOnly_.size());
  if (!s.work_.empty() && s.work_.size() != s.cells_.size()) throw par::WireError("a voxel split whose work does not match its voxels");
  for (const Node& n : s.nodes_)
    if (n.axis >= 3 || (n.axis < 0 ? n.left >= s.cells_.size() : n.left >= s.nodes_.size() || n.right >= s.nodes_.size()))
      throw par::WireError("a voxel split with a node out of range");
  return s;
}

}  // namespace pr::rt
