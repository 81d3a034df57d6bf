// The kd split of object-space partitioning: space is cut recursively until there are as many
// voxels as asked for, each cut placed so that both sides hold triangles in proportion to the
// voxels they will become (the cost estimate is the triangle count, straddlers counted on both
// sides), on the axis that balances best and duplicates the fewest triangles. Built once per
// frame by the controlling thread before the trace stage (object_space.cpp).
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

float maxAbs(glm::vec3 v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }

}  // namespace

struct VoxelSplit::Built {
  std::vector<scene::Bounds> bounds;  // per scene triangle
  std::vector<glm::vec3> centroids;
  scene::Bounds scene;                // of every finite triangle
};

VoxelSplit::VoxelSplit(const scene::Scene& s, const VoxelSplitOptions& options) : margin_(options.margin) {
  if (options.voxels < 1 || options.voxels > kMaxVoxels)
    throw InputError("object-space partitioning: " + std::to_string(options.voxels) +
                     " voxels requested, expected 1 to " + std::to_string(kMaxVoxels));
  PR_CHECK(std::isfinite(margin_) && margin_ >= 0.0f, "VoxelSplit: margin must be finite and >= 0");

  Built b;
  b.bounds.resize(s.triangles.size());
  b.centroids.resize(s.triangles.size());
  std::vector<uint32_t> all;
  all.reserve(s.triangles.size());
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    scene::Bounds box;
    for (uint32_t v : s.triangles[i].v) box.extend(s.positions[v]);
    b.bounds[i] = box;
    b.centroids[i] = box.center();
    // A triangle with a non-finite vertex can never be hit (the BVH makes it unhittable), so
    // no voxel needs it.
    if (!std::isfinite(maxAbs(box.min)) || !std::isfinite(maxAbs(box.max))) continue;
    b.scene.extend(box);
    all.push_back(static_cast<uint32_t>(i));
  }
  if (b.scene.empty()) b.scene = scene::Bounds{glm::vec3(-1.0f), glm::vec3(1.0f)};

  const scene::Bounds everywhere{glm::vec3(-kInf), glm::vec3(kInf)};
  nodes_.reserve(2 * options.voxels);
  build(b, everywhere, std::move(all), options.voxels, 0);
}

// Splits `cell` (holding `tris`: the triangles overlapping it grown by the margin) into
// `leaves` voxels. Returns the node index.
uint32_t VoxelSplit::build(Built& b, const scene::Bounds& cell, std::vector<uint32_t> tris, int leaves, int depth) {
  PR_CHECK(depth < kMaxDepth, "VoxelSplit: kd tree deeper than kMaxDepth");
  const auto index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  if (leaves == 1) {
    std::sort(tris.begin(), tris.end());
    nodes_[index].left = static_cast<uint32_t>(cells_.size());
    cells_.push_back(cell);
    triangles_.push_back(std::move(tris));
    return index;
  }

  const int nLeft = leaves / 2, nRight = leaves - nLeft;
  // Where planes may go: the cell clipped to the scene, so outer cells (infinite faces) split
  // at the geometry, not at infinity.
  scene::Bounds region{glm::max(cell.min, b.scene.min), glm::min(cell.max, b.scene.max)};
  for (int a = 0; a < 3; ++a)
    if (region.min[a] > region.max[a]) region.min[a] = region.max[a] = std::clamp(b.scene.center()[a], cell.min[a], cell.max[a]);

  int bestAxis = -1;
  float bestPlane = 0.0f;
  double bestScore = std::numeric_limits<double>::infinity();
  std::vector<float> coords;
  coords.reserve(tris.size());
  for (int a = 0; a < 3; ++a) {
    // The plane with nLeft/leaves of the triangles' centroids below it (clamped into the
    // region, since a straddler's centroid may lie outside this cell).
    coords.clear();
    for (uint32_t t : tris) coords.push_back(std::clamp(b.centroids[t][a], region.min[a], region.max[a]));
    float plane = 0.5f * (region.min[a] + region.max[a]);
    const size_t m = coords.size();
    const size_t k = (m * nLeft + leaves / 2) / leaves;
    if (k > 0 && k < m) {
      std::nth_element(coords.begin(), coords.begin() + k, coords.end());
      const float above = coords[k];
      const float below = *std::max_element(coords.begin(), coords.begin() + k);
      plane = below + 0.5f * (above - below);
    }
    // Estimated cost per side: the triangles each side will hold, per voxel it becomes.
    size_t left = 0, right = 0;
    for (uint32_t t : tris) {
      if (b.bounds[t].min[a] <= plane + margin_) ++left;
      if (b.bounds[t].max[a] >= plane - margin_) ++right;
    }
    const double score = std::max(double(left) / nLeft, double(right) / nRight);
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
  scene::Bounds leftCell = cell, rightCell = cell;
  leftCell.max[a] = bestPlane;
  rightCell.min[a] = bestPlane;
  const uint32_t l = build(b, leftCell, std::move(leftTris), nLeft, depth + 1);
  const uint32_t r = build(b, rightCell, std::move(rightTris), nRight, depth + 1);
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

std::vector<int> assignVoxelOwners(const VoxelSplit& split, int pes) {
  PR_CHECK(pes >= 1, "assignVoxelOwners: at least one PE");
  const int n = split.voxels();
  std::vector<int> owners(n, 0);
  if (n == pes) {
    std::iota(owners.begin(), owners.end(), 0);
    return owners;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return split.triangles(x).size() > split.triangles(y).size(); });
  std::vector<size_t> load(pes, 0);
  for (int v : order) {
    const int pe = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    owners[v] = pe;
    // An empty voxel still costs its traversal: count it as one triangle.
    load[pe] += std::max<size_t>(1, split.triangles(v).size());
  }
  return owners;
}

}  // namespace pr::rt
