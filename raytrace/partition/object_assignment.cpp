// Object partitioning's data split: scene objects cut into pieces of bounded size by spatial
// median splits, the pieces rays reach most per triangle replicated within a budget, and the
// others dealt to PEs in runs of equal triangle count along a Morton curve.
// Built once per frame on the assembler's PE in the "split" stage (object_partition.cpp);
// read-only afterwards.
#include "raytrace/partition/object_assignment.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "common/util/error.h"

namespace pr::rt {
namespace {

constexpr int kMaxPes = 4096;
constexpr uint32_t kMinPieceTriangles = 64;

scene::Bounds boundsOf(const scene::Scene& s, std::span<const uint32_t> tris) {
  scene::Bounds b;
  for (uint32_t t : tris)
    for (uint32_t v : s.triangles[t].v) b.extend(s.positions[v]);
  return b;
}

// Every triangle's centroid, computed once: the cuts read them at every level.
std::vector<glm::vec3> centroids(const scene::Scene& s) {
  std::vector<glm::vec3> out(s.triangles.size());
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    const scene::Triangle& tri = s.triangles[t];
    out[t] = (s.positions[tri.v[0]] + s.positions[tri.v[1]] + s.positions[tri.v[2]]) * (1.0f / 3.0f);
  }
  return out;
}

// Cuts `tris` in two at the middle of its centroids' extent on the longest axis until each
// part holds at most maxTriangles; when every centroid lies on one side of the middle (all at
// one point), the cut falls back to the median triangle so it always makes progress.
void splitPiece(const scene::Scene& s, std::span<const glm::vec3> centroid, uint32_t object, std::vector<uint32_t> tris,
                uint32_t maxTriangles, std::vector<ObjectPiece>& out) {
  if (tris.size() <= maxTriangles) {
    if (!std::is_sorted(tris.begin(), tris.end())) std::sort(tris.begin(), tris.end());  // after a median cut
    ObjectPiece piece;
    piece.object = object;
    piece.bounds = boundsOf(s, tris);
    piece.triangles = std::move(tris);
    out.push_back(std::move(piece));
    return;
  }
  scene::Bounds c;
  for (uint32_t t : tris) c.extend(centroid[t]);
  const glm::vec3 e = c.extent();
  const int axis = e.x >= e.y ? (e.x >= e.z ? 0 : 2) : (e.y >= e.z ? 1 : 2);
  const float middle = c.center()[axis];
  // Stable, so each part stays in ascending order.
  auto mid = std::stable_partition(tris.begin(), tris.end(), [&](uint32_t t) { return centroid[t][axis] < middle; });
  if (mid == tris.begin() || mid == tris.end()) {
    mid = tris.begin() + tris.size() / 2;
    std::nth_element(tris.begin(), mid, tris.end(), [&](uint32_t x, uint32_t y) {
      const float cx = centroid[x][axis], cy = centroid[y][axis];
      return cx < cy || (cx == cy && x < y);
    });
  }
  std::vector<uint32_t> upper(mid, tris.end());
  tris.erase(mid, tris.end());
  splitPiece(s, centroid, object, std::move(tris), maxTriangles, out);
  splitPiece(s, centroid, object, std::move(upper), maxTriangles, out);
}

// 21 bits per axis of the point's place in the cube around the box, interleaved (a cube, so
// that a long, flat scene is cut across its length first).
uint64_t mortonKey(glm::vec3 p, const scene::Bounds& box) {
  auto spread = [](uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
  };
  const glm::vec3 size = box.max - box.min;
  const float extent = std::max(size.x, std::max(size.y, size.z));
  uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const float f = extent > 0.0f ? std::clamp((p[a] - box.min[a]) / extent, 0.0f, 1.0f) : 0.0f;
    key |= spread(uint64_t(f * float(0x1fffff))) << a;
  }
  return key;
}

}  // namespace

ObjectAssignment::ObjectAssignment(const scene::Scene& s, const ObjectAssignmentOptions& options)
    : margin_(options.margin) {
  const int pes = options.pes;
  if (pes < 1 || pes > kMaxPes)
    throw InputError("object partitioning: " + std::to_string(pes) + " PEs requested, expected 1 to " +
                     std::to_string(kMaxPes));
  PR_CHECK(std::isfinite(margin_) && margin_ >= 0.0f, "ObjectAssignment: margin must be finite and >= 0");
  const auto total = static_cast<uint32_t>(s.triangles.size());
  const uint32_t maxPiece = options.maxPieceTriangles > 0
                                ? options.maxPieceTriangles
                                : std::max(kMinPieceTriangles, (total + 4 * pes - 1) / (4 * pes));

  // Objects as the loader recorded them; triangles outside every object (scenes built in code)
  // form one more object.
  const std::vector<glm::vec3> centroid = centroids(s);
  std::vector<bool> covered(total, false);
  for (size_t o = 0; o < s.objects.size(); ++o) {
    const scene::Object& obj = s.objects[o];
    PR_CHECK(uint64_t(obj.firstTriangle) + obj.triangleCount <= total, "ObjectAssignment: object range out of the scene");
    std::vector<uint32_t> tris(obj.triangleCount);
    std::iota(tris.begin(), tris.end(), obj.firstTriangle);
    for (uint32_t t : tris) covered[t] = true;
    if (!tris.empty()) splitPiece(s, centroid, static_cast<uint32_t>(o), std::move(tris), maxPiece, pieces_);
  }
  std::vector<uint32_t> rest;
  for (uint32_t t = 0; t < total; ++t)
    if (!covered[t]) rest.push_back(t);
  if (!rest.empty()) splitPiece(s, centroid, static_cast<uint32_t>(s.objects.size()), std::move(rest), maxPiece, pieces_);

  // Replicated pieces, most reached per triangle first (ties: the lower piece), while they fit
  // the budget.
  uint64_t budget = pes > 1 ? uint64_t(std::max(0.0, options.replicatedFraction) * double(total)) : 0;
  if (budget > 0) {
    auto exposure = [&](const ObjectPiece& p) {
      const glm::vec3 e = p.bounds.extent();
      return (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x) / double(p.triangles.size());
    };
    std::vector<uint32_t> order(pieces_.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return exposure(pieces_[x]) > exposure(pieces_[y]); });
    for (uint32_t p : order) {
      ObjectPiece& piece = pieces_[p];
      if (piece.bounds.empty() || piece.triangles.size() > budget) continue;
      budget -= piece.triangles.size();
      piece.owner = kEveryPe;
      replicated_.insert(replicated_.end(), piece.triangles.begin(), piece.triangles.end());
    }
    std::sort(replicated_.begin(), replicated_.end());
  }

  // The other pieces in the order of a Morton curve through their centres, cut into P runs of
  // about equal triangle count: each PE owns a compact region of the scene, so a ray is
  // answered by few owners (often by its originator's own pieces alone) and an owner's part of
  // the directory is one subtree the walk skips whole (owner_directory.h).
  scene::Bounds all;
  for (const ObjectPiece& p : pieces_) all.extend(p.bounds);
  std::vector<uint64_t> key(pieces_.size());
  for (size_t p = 0; p < pieces_.size(); ++p) key[p] = mortonKey(pieces_[p].bounds.center(), all);
  for (uint32_t p = 0; p < pieces_.size(); ++p)
    if (pieces_[p].owner != kEveryPe) curveOrder_.push_back(p);
  std::stable_sort(curveOrder_.begin(), curveOrder_.end(), [&](uint32_t x, uint32_t y) { return key[x] < key[y]; });
  const uint64_t owned = total - replicated_.size();
  uint64_t before = 0;  // triangles of the pieces before this one on the curve
  for (uint32_t p : curveOrder_) {
    const uint64_t n = pieces_[p].triangles.size();
    // The PE whose share of the curve holds the piece's middle triangle.
    const uint64_t middle = before + n / 2;
    pieces_[p].owner = int(std::min<uint64_t>(uint64_t(pes) - 1, middle * uint64_t(pes) / std::max<uint64_t>(1, owned)));
    before += n;
  }

  perPe_.assign(pes, {});
  piecesOf_.assign(pes, {});
  for (uint32_t p = 0; p < pieces_.size(); ++p) {
    const ObjectPiece& piece = pieces_[p];
    if (piece.owner == kEveryPe) continue;
    piecesOf_[piece.owner].push_back(p);
    perPe_[piece.owner].insert(perPe_[piece.owner].end(), piece.triangles.begin(), piece.triangles.end());
  }
  for (auto& tris : perPe_) std::sort(tris.begin(), tris.end());
}

}  // namespace pr::rt
