// Object partitioning's data split: scene objects cut into pieces of bounded size by spatial
// median splits, pieces dealt to PEs largest first to the least loaded PE, and the test that
// decides which owners a ray must visit. Built once per frame by the controlling thread,
// before the trace stage (object_partition.cpp); read-only afterwards.
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

glm::vec3 centroid(const scene::Scene& s, uint32_t t) {
  const scene::Triangle& tri = s.triangles[t];
  return (s.positions[tri.v[0]] + s.positions[tri.v[1]] + s.positions[tri.v[2]]) * (1.0f / 3.0f);
}

// Cuts `tris` in two at the middle of its centroids' extent on the longest axis until each
// part holds at most maxTriangles; when every centroid lies on one side of the middle (all at
// one point), the cut falls back to the median triangle so it always makes progress.
void splitPiece(const scene::Scene& s, uint32_t object, std::vector<uint32_t> tris, uint32_t maxTriangles,
                std::vector<ObjectPiece>& out) {
  if (tris.size() <= maxTriangles) {
    std::sort(tris.begin(), tris.end());
    ObjectPiece piece;
    piece.object = object;
    piece.bounds = boundsOf(s, tris);
    piece.triangles = std::move(tris);
    out.push_back(std::move(piece));
    return;
  }
  scene::Bounds c;
  for (uint32_t t : tris) c.extend(centroid(s, t));
  const glm::vec3 e = c.extent();
  const int axis = e.x >= e.y ? (e.x >= e.z ? 0 : 2) : (e.y >= e.z ? 1 : 2);
  const float middle = c.center()[axis];
  auto mid = std::partition(tris.begin(), tris.end(), [&](uint32_t t) { return centroid(s, t)[axis] < middle; });
  if (mid == tris.begin() || mid == tris.end()) {
    mid = tris.begin() + tris.size() / 2;
    std::nth_element(tris.begin(), mid, tris.end(), [&](uint32_t x, uint32_t y) {
      const float cx = centroid(s, x)[axis], cy = centroid(s, y)[axis];
      return cx < cy || (cx == cy && x < y);
    });
  }
  std::vector<uint32_t> upper(mid, tris.end());
  tris.erase(mid, tris.end());
  splitPiece(s, object, std::move(tris), maxTriangles, out);
  splitPiece(s, object, std::move(upper), maxTriangles, out);
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
  std::vector<bool> covered(total, false);
  for (size_t o = 0; o < s.objects.size(); ++o) {
    const scene::Object& obj = s.objects[o];
    PR_CHECK(uint64_t(obj.firstTriangle) + obj.triangleCount <= total, "ObjectAssignment: object range out of the scene");
    std::vector<uint32_t> tris(obj.triangleCount);
    std::iota(tris.begin(), tris.end(), obj.firstTriangle);
    for (uint32_t t : tris) covered[t] = true;
    if (!tris.empty()) splitPiece(s, static_cast<uint32_t>(o), std::move(tris), maxPiece, pieces_);
  }
  std::vector<uint32_t> rest;
  for (uint32_t t = 0; t < total; ++t)
    if (!covered[t]) rest.push_back(t);
  if (!rest.empty()) splitPiece(s, static_cast<uint32_t>(s.objects.size()), std::move(rest), maxPiece, pieces_);

  // Longest processing time first: largest piece to the least loaded PE (ties: lower piece,
  // lower PE), within 4/3 of the optimal makespan (Graham 1969).
  std::vector<uint32_t> order(pieces_.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t x, uint32_t y) { return pieces_[x].triangles.size() > pieces_[y].triangles.size(); });
  std::vector<size_t> load(pes, 0);
  for (uint32_t p : order) {
    const int pe = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    pieces_[p].owner = pe;
    load[pe] += pieces_[p].triangles.size();
  }

  perPe_.assign(pes, {});
  piecesOf_.assign(pes, {});
  for (uint32_t p = 0; p < pieces_.size(); ++p) {
    const ObjectPiece& piece = pieces_[p];
    piecesOf_[piece.owner].push_back(p);
    perPe_[piece.owner].insert(perPe_[piece.owner].end(), piece.triangles.begin(), piece.triangles.end());
  }
  for (auto& tris : perPe_) std::sort(tris.begin(), tris.end());
}

void ObjectAssignment::ownersAlong(const Ray& ray, std::vector<int>& owners) const {
  owners.clear();
  for (int pe = 0; pe < pes(); ++pe)
    for (uint32_t p : piecesOf_[pe])
      if (rayReachesBox(ray, pieces_[p].bounds, margin_)) {
        owners.push_back(pe);
        break;
      }
}

bool rayReachesBox(const Ray& ray, const scene::Bounds& box, float margin) {
  if (box.empty()) return false;
  // Rounding of (b - o) / d is below gamma(3) relative (Ize 2013); widening the far distance by
  // 1 + 2 gamma(3) keeps every box the ray touches.
  constexpr float kUlp = 0x1p-24f;
  constexpr float kFarScale = 1.0f + 2.0f * (3.0f * kUlp) / (1.0f - 3.0f * kUlp);
  float t0 = ray.tMin, t1 = ray.tMax;
  for (int a = 0; a < 3; ++a) {
    const float lo = box.min[a] - margin, hi = box.max[a] + margin;
    const float o = ray.origin[a], d = ray.direction[a];
    if (d == 0.0f) {
      if (o < lo || o > hi) return false;
      continue;
    }
    float tNear = (lo - o) / d, tFar = (hi - o) / d;
    if (tNear > tFar) std::swap(tNear, tFar);
    tFar *= kFarScale;
    t0 = tNear > t0 ? tNear : t0;
    t1 = tFar < t1 ? tFar : t1;
    if (!(t0 <= t1)) return false;
  }
  return true;
}

}  // namespace pr::rt
