// The kd split of object-space partitioning: space is cut recursively until there are as many
// voxels as asked for, each cut placed so that both sides hold estimated cost in proportion to
// the voxels they will become (the weight of the work points on each side when given, else the
// triangle count, straddlers counted on both sides), on the axis that balances best and
// duplicates the fewest triangles. Then each voxel's content boxes. Built once per frame on
// the assembler's PE in the "split" stage (object_space.cpp).
#include "raytrace/partition/voxel_split.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "common/util/error.h"

namespace pr::rt {
namespace {

constexpr int kMaxVoxels = 4096;
constexpr float kInf = std::numeric_limits<float>::infinity();

bool allFinite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

struct VoxelSplit::Built {
  std::vector<scene::Bounds> bounds;  // per scene triangle
  scene::Bounds scene;                // of every finite triangle
  std::span<const WorkPoint> work;    // the options' work points
  std::vector<uint32_t> replicated;   // the options', ascending
};

namespace {

// The plane on `axis` inside [lo, hi] with `below` of the points' weight under it: the weighted
// quantile, found in bins (exact to a bin's width, interpolated within it).
float workQuantile(std::span<const WorkPoint> work, const std::vector<uint32_t>& points, int axis, float lo, float hi,
                   double below) {
  constexpr int kBins = 1024;
  if (!(hi > lo)) return lo;
  std::vector<double> bins(kBins, 0.0);
  const double scale = double(kBins) / (double(hi) - double(lo));
  auto bin = [&](float x) { return int(std::clamp((double(x) - double(lo)) * scale, 0.0, double(kBins - 1))); };
  for (uint32_t p : points) bins[size_t(bin(work[p].position[axis]))] += work[p].weight;
  double sum = 0.0;
  for (int i = 0; i < kBins; ++i) {
    if (sum + bins[size_t(i)] >= below && bins[size_t(i)] > 0.0) {
      const double frac = std::clamp((below - sum) / bins[size_t(i)], 0.0, 1.0);
      return std::clamp(float(double(lo) + (double(i) + frac) / scale), lo, hi);
    }
    sum += bins[size_t(i)];
  }
  return hi;
}

}  // namespace

VoxelSplit::VoxelSplit(const scene::Scene& s, const VoxelSplitOptions& options)
    : margin_(options.margin) {
  if (options.voxels < 1 || options.voxels > kMaxVoxels)
    throw InputError("object-space partitioning: " + std::to_string(options.voxels) +
                     " voxels requested, expected 1 to " + std::to_string(kMaxVoxels));
  PR_CHECK(std::isfinite(margin_) && margin_ >= 0.0f, "VoxelSplit: margin must be finite and >= 0");

  Built b;
  b.replicated.assign(options.replicated.begin(), options.replicated.end());
  std::sort(b.replicated.begin(), b.replicated.end());
  b.bounds.resize(s.triangles.size());
  std::vector<uint32_t> all;
  all.reserve(s.triangles.size());
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    scene::Bounds box;
    for (uint32_t v : s.triangles[i].v) box.extend(s.positions[v]);
    b.bounds[i] = box;
    // A triangle with a non-finite vertex can never be hit (the BVH makes it unhittable), so
    // no voxel needs it.
    if (!(allFinite(box.min) && allFinite(box.max))) continue;
    b.scene.extend(box);
    all.push_back(static_cast<uint32_t>(i));
  }
  if (b.scene.empty()) b.scene = scene::Bounds{glm::vec3(-1.0f), glm::vec3(1.0f)};

  // Work points that count: finite, with weight.
  std::vector<uint32_t> points;
  for (size_t i = 0; i < options.work.size(); ++i) {
    const WorkPoint& w = options.work[i];
    if (w.weight > 0.0f && std::isfinite(w.weight) && allFinite(w.position)) points.push_back(uint32_t(i));
  }
  if (!points.empty()) {
    b.work = options.work;
    work_.reserve(size_t(options.voxels));
  }

  const scene::Bounds everywhere{glm::vec3(-kInf), glm::vec3(kInf)};
  nodes_.reserve(2 * options.voxels);
  build(b, everywhere, std::move(all), std::move(points), options.voxels, 0);
  buildContent(s, b);
}

void VoxelSplit::buildContent(const scene::Scene& s, const Built& b) {
  std::vector<uint32_t> objectOf(s.triangles.size(), static_cast<uint32_t>(s.objects.size()));
  for (size_t o = 0; o < s.objects.size(); ++o)
    for (uint32_t t = s.objects[o].firstTriangle; t < s.objects[o].firstTriangle + s.objects[o].triangleCount; ++t)
      objectOf[t] = static_cast<uint32_t>(o);
  const glm::vec3 grow(2.0f * margin_);  // the cell as its triangles were chosen, and more
  std::vector<scene::Bounds> boxes;
  // One set of boxes over the voxel's triangles for which keep(t) holds.
  auto addBoxes = [&](size_t v, auto keep, std::vector<SlabBoxes4>& content, std::vector<uint32_t>& first) {
    const scene::Bounds cell{cells_[v].min - grow, cells_[v].max + grow};
    // A voxel's triangles ascend, and an object's are one range: one box per run of an object.
    boxes.clear();
    uint32_t object = ~0u;
    for (uint32_t t : triangles_[v]) {
      if (!keep(t)) continue;
      const scene::Bounds part{glm::max(b.bounds[t].min, cell.min), glm::min(b.bounds[t].max, cell.max)};
      if (part.min.x > part.max.x || part.min.y > part.max.y || part.min.z > part.max.z) continue;
      if (boxes.empty() || objectOf[t] != object) boxes.emplace_back();
      object = objectOf[t];
      boxes.back().extend(part);
    }
    auto area = [](const scene::Bounds& x) {
      const glm::vec3 e = x.extent();
      return double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x;
    };
    if (boxes.size() > size_t(kContentBoxes)) {
      std::stable_sort(boxes.begin(), boxes.end(), [&](const scene::Bounds& x, const scene::Bounds& y) { return area(x) > area(y); });
      for (size_t i = kContentBoxes; i < boxes.size(); ++i) boxes[kContentBoxes - 1].extend(boxes[i]);
      boxes.resize(kContentBoxes);
    }
    for (size_t i = 0; i < boxes.size(); i += 4) content.push_back(SlabBoxes4::of(&boxes[i], boxes.size() - i, margin_));
    first.push_back(static_cast<uint32_t>(content.size()));
  };
  contentFirst_.assign(1, 0);
  for (size_t v = 0; v < cells_.size(); ++v) addBoxes(v, [](uint32_t) { return true; }, content_, contentFirst_);
  if (b.replicated.empty()) return;  // the held-only boxes are the content boxes
  heldOnlyFirst_.assign(1, 0);
  for (size_t v = 0; v < cells_.size(); ++v)
    addBoxes(v, [&](uint32_t t) { return !std::binary_search(b.replicated.begin(), b.replicated.end(), t); }, heldOnly_,
             heldOnlyFirst_);
}

// Splits `cell` (holding `tris`: the triangles overlapping it grown by the margin) into
// `leaves` voxels. Returns the node index.
uint32_t VoxelSplit::build(Built& b, const scene::Bounds& cell, std::vector<uint32_t> tris, std::vector<uint32_t> points,
                           int leaves, int depth) {
  PR_CHECK(depth < kMaxDepth, "VoxelSplit: kd tree deeper than kMaxDepth");
  const auto index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  double work = 0.0;
  for (uint32_t p : points) work += b.work[p].weight;
  if (leaves == 1) {
    // Ascending already: the cuts keep the order of the scene's triangles.
    PR_CHECK(std::is_sorted(tris.begin(), tris.end()), "VoxelSplit: a voxel's triangles out of order");
    nodes_[index].left = static_cast<uint32_t>(cells_.size());
    cells_.push_back(cell);
    triangles_.push_back(std::move(tris));
    if (!b.work.empty()) work_.push_back(work);
    return index;
  }

  const int nLeft = leaves / 2, nRight = leaves - nLeft;
  // Where planes may go: the cell clipped to the scene, so outer cells (infinite faces) split
  // at the geometry, not at infinity.
  scene::Bounds region{glm::max(cell.min, b.scene.min), glm::min(cell.max, b.scene.max)};
  for (int a = 0; a < 3; ++a)
    if (region.min[a] > region.max[a]) region.min[a] = region.max[a] = std::clamp(b.scene.center()[a], cell.min[a], cell.max[a]);

  // Per axis, the plane with nLeft/leaves of the cost below it.
  float planes[3];
  std::vector<float> coords;
  coords.reserve(work > 0.0 ? 0 : tris.size());
  for (int a = 0; a < 3; ++a) {
    float plane = 0.5f * (region.min[a] + region.max[a]);
    if (work > 0.0) {
      // The quantile, moved to the middle of the gap between the points on either side of it
      // (as the median is between centroids), so a plane between two walls stays clear of both.
      const float q = workQuantile(b.work, points, a, region.min[a], region.max[a], work * nLeft / leaves);
      float lower = -kInf, upper = kInf;
      for (uint32_t p : points) {
        const float x = std::clamp(b.work[p].position[a], region.min[a], region.max[a]);
        if (x <= q) lower = std::max(lower, x);
        else upper = std::min(upper, x);
      }
      plane = lower > -kInf && upper < kInf ? lower + 0.5f * (upper - lower) : q;
    } else {
      // The triangles' centroids (clamped into the region, since a straddler's centroid may lie
      // outside this cell): the median, between the centroids on either side of it.
      coords.clear();
      for (uint32_t t : tris) coords.push_back(std::clamp(b.bounds[t].center()[a], region.min[a], region.max[a]));
      const size_t m = coords.size();
      const size_t k = (m * nLeft + leaves / 2) / leaves;
      if (k > 0 && k < m) {
        std::nth_element(coords.begin(), coords.begin() + k, coords.end());
        const float above = coords[k];
        const float below = *std::max_element(coords.begin(), coords.begin() + k);
        plane = below + 0.5f * (above - below);
      }
    }
    planes[a] = plane;
  }
  // The triangles each side of each axis's plane will hold (straddlers on both), in one pass
  // over the triangles' bounds (the cost of a cut on a million triangles is reading them).
  size_t left[3] = {0, 0, 0}, right[3] = {0, 0, 0};
  for (uint32_t t : tris) {
    const scene::Bounds& box = b.bounds[t];
    for (int a = 0; a < 3; ++a) {
      left[a] += box.min[a] <= planes[a] + margin_ ? 1 : 0;
      right[a] += box.max[a] >= planes[a] - margin_ ? 1 : 0;
    }
  }

  int bestAxis = -1;
  float bestPlane = 0.0f;
  double bestScore = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const float plane = planes[a];
    // Estimated cost per side: the triangles each side will hold, per voxel it becomes.
    double score = std::max(double(left[a]) / nLeft, double(right[a]) / nRight);
    if (work > 0.0) {
      // The work per voxel against an even share (1 when balanced), plus the fraction of the
      // triangles the plane duplicates.
      double workLeft = 0.0;
      for (uint32_t p : points)
        if (b.work[p].position[a] < plane) workLeft += b.work[p].weight;
      const double balance = std::max(workLeft / nLeft, (work - workLeft) / nRight) / (work / leaves);
      score = balance + double(left[a] + right[a] - tris.size()) / double(std::max<size_t>(1, tris.size()));
    }
    const float extent = region.max[a] - region.min[a];
    const bool better = bestAxis < 0 || score < bestScore ||
                        (score == bestScore && extent > region.max[bestAxis] - region.min[bestAxis]);
    if (better) {
      bestAxis = a;
      bestPlane = plane;
      bestScore = score;
    }
  }

  const int a = bestAxis;
  std::vector<uint32_t> leftTris, rightTris;
  for (uint32_t t : tris) {
    if (b.bounds[t].min[a] <= bestPlane + margin_) leftTris.push_back(t);
    if (b.bounds[t].max[a] >= bestPlane - margin_) rightTris.push_back(t);
  }
  tris.clear();
  tris.shrink_to_fit();
  // A point on the plane belongs to the upper side, as in voxelAt.
  std::vector<uint32_t> leftPoints, rightPoints;
  for (uint32_t p : points) (b.work[p].position[a] < bestPlane ? leftPoints : rightPoints).push_back(p);
  points.clear();
  points.shrink_to_fit();
  scene::Bounds leftCell = cell, rightCell = cell;
  leftCell.max[a] = bestPlane;
  rightCell.min[a] = bestPlane;
  const uint32_t l = build(b, leftCell, std::move(leftTris), std::move(leftPoints), nLeft, depth + 1);
  const uint32_t r = build(b, rightCell, std::move(rightTris), std::move(rightPoints), nRight, depth + 1);
  nodes_[index] = Node{a, bestPlane, l, r};
  return index;
}

int VoxelSplit::voxelAt(glm::vec3 p) const {
  PR_CHECK(!nodes_.empty(), "VoxelSplit: empty split");
  uint32_t node = 0;
  while (nodes_[node].axis >= 0) {
    const Node& n = nodes_[node];
    node = p[n.axis] < n.split ? n.left : n.right;
  }
  return static_cast<int>(nodes_[node].left);
}

size_t VoxelSplit::storedTriangles() const {
  size_t n = 0;
  for (const auto& t : triangles_) n += t.size();
  return n;
}

std::vector<VoxelSpan> VoxelSplit::spans(const Ray& ray) const {
  std::vector<VoxelSpan> out;
  walk(ray, [&](const VoxelSpan& s) {
    out.push_back(s);
    return true;
  });
  return out;
}

std::vector<int> assignVoxelOwners(const VoxelSplit& split, int pes, float triangleWork) {
  PR_CHECK(pes >= 1, "assignVoxelOwners: at least one PE");
  PR_CHECK(std::isfinite(triangleWork) && triangleWork >= 0.0f, "assignVoxelOwners: triangle work must be finite and >= 0");
  const int n = split.voxels();
  std::vector<int> owners(n, 0);
  if (n == pes) {
    std::iota(owners.begin(), owners.end(), 0);
    return owners;
  }
  // Without work points an empty voxel still costs its traversal: it counts as one triangle.
  auto cost = [&](int v) {
    const double triangles = double(split.triangles(v).size());
    return split.hasWork() ? split.work(v) + double(triangleWork) * triangles : std::max(1.0, triangles);
  };
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return cost(x) > cost(y); });
  std::vector<double> load(pes, 0.0);
  for (int v : order) {
    const int pe = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    owners[v] = pe;
    load[pe] += cost(v);
  }
  return owners;
}

}  // namespace pr::rt
