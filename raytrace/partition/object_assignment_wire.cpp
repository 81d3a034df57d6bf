// The object assignment's encoding (object_assignment.h): its margin, then each piece (object,
// owner, bounds, triangles), each PE's triangles and pieces, the Morton curve's order and the
// replicated triangles, every list a sequence. Rank 0 makes the assignment once and sends it.
#include <type_traits>

#include "raytrace/partition/object_assignment.h"

namespace pr::rt {
namespace {

void encodeLists(par::WireWriter& w, const std::vector<std::vector<uint32_t>>& lists) {
  w.value(std::uint64_t(lists.size()));
  for (const std::vector<uint32_t>& l : lists) w.sequence(std::span<const uint32_t>(l));
}

std::vector<std::vector<uint32_t>> decodeLists(par::WireReader& r) {
  const auto n = r.value<std::uint64_t>();
  if (n > r.remaining() / sizeof(std::uint64_t)) throw par::WireError("more lists than their message holds");
  std::vector<std::vector<uint32_t>> lists(static_cast<std::size_t>(n));
  for (std::vector<uint32_t>& l : lists) l = r.sequence<uint32_t>();
  return lists;
}

}  // namespace

void ObjectAssignment::encode(par::WireWriter& w) const {
  static_assert(std::is_trivially_copyable_v<scene::Bounds>);
  w.value(margin_);
  w.value(std::uint64_t(pieces_.size()));
  for (const ObjectPiece& piece : pieces_) {
    w.value(piece.object);
    w.value(std::int32_t(piece.owner));
    w.value(piece.bounds);
    w.sequence(std::span<const uint32_t>(piece.triangles));
  }
  encodeLists(w, perPe_);
  encodeLists(w, piecesOf_);
  w.sequence(std::span<const uint32_t>(curveOrder_));
  w.sequence(std::span<const uint32_t>(replicated_));
}

ObjectAssignment ObjectAssignment::decode(par::WireReader& r) {
  ObjectAssignment a;
  a.margin_ = r.value<float>();
  const auto pieces = r.value<std::uint64_t>();
  if (pieces > r.remaining() / sizeof(std::uint64_t)) throw par::WireError("more pieces than their message holds");
  a.pieces_.resize(static_cast<std::size_t>(pieces));
  for (ObjectPiece& piece : a.pieces_) {
    piece.object = r.value<uint32_t>();
    piece.owner = r.value<std::int32_t>();
    piece.bounds = r.value<scene::Bounds>();
    piece.triangles = r.sequence<uint32_t>();
  }
  a.perPe_ = decodeLists(r);
  a.piecesOf_ = decodeLists(r);
  a.curveOrder_ = r.sequence<uint32_t>();
  a.replicated_ = r.sequence<uint32_t>();
  // Owners and piece indices are used as indices: one out of range would read past a table.
  const int pes = a.pes();
  if (a.piecesOf_.size() != a.perPe_.size()) throw par::WireError("an object assignment whose PE lists differ in length");
  for (const ObjectPiece& piece : a.pieces_)
    if (piece.owner != kEveryPe && (piece.owner < 0 || piece.owner >= pes))
      throw par::WireError("an object assignment with a piece owner out of range");
  const auto checkPieces = [&](std::span<const uint32_t> ids) {
    for (uint32_t id : ids)
      if (id >= a.pieces_.size()) throw par::WireError("an object assignment naming a piece out of range");
  };
  for (const std::vector<uint32_t>& l : a.piecesOf_) checkPieces(l);
  checkPieces(a.curveOrder_);
  return a;
}

}  // namespace pr::rt
