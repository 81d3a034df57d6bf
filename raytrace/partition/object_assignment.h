// ObjectAssignment: the data split of object partitioning (seed section 5.1.2). Objects are the
// scene's glTF mesh primitives (Scene::objects), split further by spatial median when large;
// the pieces are assigned to PEs in runs of about equal triangle count along a Morton curve
// through their centres, so each PE owns a compact region. A few small pieces that rays reach
// most may instead be replicated on every PE. object_partition.cpp builds each PE's BVH over
// its own triangles (and one over the replicated ones) and asks only the owners whose bounds a
// ray can reach (owner_directory.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/parallel/wire.h"
#include "common/scene/scene.h"
#include "raytrace/core/ray.h"

namespace pr::rt {

// The owner of a replicated piece: every PE holds a copy and answers for it itself.
inline constexpr int kEveryPe = -2;

struct ObjectAssignmentOptions {
  int pes = 1;
  // A piece never holds more triangles than this; 0 = max(64, ceil(triangles / (4 P))), so
  // every PE gets several pieces and the greedy assignment can balance them.
  uint32_t maxPieceTriangles = 0;
  // Piece bounds are grown by this much (partitionMargin, partition_margin.h) before rays are
  // tested against them, so an owner whose triangle a ray hits is never skipped.
  float margin = 0.0f;
  // With P > 1, pieces every PE holds a copy of: those rays reach most per triangle (the
  // largest bounds surface area per triangle, which random rays cross in proportion to; a
  // floor of two triangles under the whole scene comes first), taken in that order while
  // their triangles stay within this fraction of the scene's. Asking one owner about them for
  // nearly every ray would cost more than the copies.
  double replicatedFraction = 0.0;
};

// A part of one scene object: its triangles (scene indices, ascending) and their bounds.
struct ObjectPiece {
  uint32_t object = 0;  // index into Scene::objects; Scene::objects.size() for triangles in none
  int owner = 0;  // kEveryPe: replicated
  std::vector<uint32_t> triangles;
  scene::Bounds bounds;  // of the triangles' vertices, not grown
};

class ObjectAssignment {
 public:
  ObjectAssignment() = default;
  // Throws pr::InputError for pes outside [1, 4096].
  ObjectAssignment(const scene::Scene& scene, const ObjectAssignmentOptions& options);

  int pes() const { return static_cast<int>(perPe_.size()); }
  float margin() const { return margin_; }
  std::span<const ObjectPiece> pieces() const { return pieces_; }
  // The triangles PE `pe` owns (the union of its pieces), ascending scene indices.
  std::span<const uint32_t> triangles(int pe) const { return perPe_[pe]; }
  // Indices into pieces() of the pieces PE `pe` owns.
  std::span<const uint32_t> piecesOf(int pe) const { return piecesOf_[pe]; }
  // Scene triangles of the replicated pieces, ascending: every PE holds them besides its own.
  std::span<const uint32_t> replicated() const { return replicated_; }
  // Indices into pieces() of the pieces PEs own, along the Morton curve: each PE's pieces are
  // one run of it.
  std::span<const uint32_t> curveOrder() const { return curveOrder_; }
  // Bytes of the directory every PE keeps to route rays: each piece's bounds and owner.
  size_t directoryBytes() const { return pieces_.size() * (sizeof(scene::Bounds) + sizeof(int)); }

  // The whole assignment as bytes (object_assignment_wire.cpp), and back: a rank that decodes
  // it holds and routes by the same pieces as the rank that made it. decode throws
  // par::WireError for bytes that are not an encoding.
  void encode(par::WireWriter& w) const;
  static ObjectAssignment decode(par::WireReader& r);

 private:
  std::vector<ObjectPiece> pieces_;
  std::vector<std::vector<uint32_t>> perPe_;
  std::vector<std::vector<uint32_t>> piecesOf_;
  std::vector<uint32_t> curveOrder_;
  std::vector<uint32_t> replicated_;
  float margin_ = 0.0f;
};

}  // namespace pr::rt
