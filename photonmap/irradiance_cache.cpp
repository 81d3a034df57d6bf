// The irradiance cache (see irradiance_cache.h): octree insert with neighbour clamping, and the
// gradient-extrapolated weighted interpolation.
#include "photonmap/irradiance_cache.h"

#include <algorithm>
#include <cmath>

namespace pr::pm {

namespace {
// The octree stops here: a record smaller than the root / 2^20 shares a node with others.
constexpr int kMaxDepth = 20;
// A record whose plane lies this far (times R_i) in front of x saw a different surface region
// (Ward: "in front of" test), e.g. the inside of a corner seen from its outside.
constexpr float kFrontTolerance = 0.05f;
// Caps 1/eps for a query exactly at a record.
constexpr float kMaxWeight = 1.0e6f;
}  // namespace

IrradianceCache::IrradianceCache(const scene::Bounds& bounds, float accuracy) : accuracy_(accuracy) {
  Node root;
  const glm::vec3 extent = bounds.extent();
  root.centre = bounds.empty() ? glm::vec3(0.0f) : bounds.center();
  // A little larger than the scene: records on its faces lie strictly inside the root.
  root.half = std::max(0.5f * std::max(extent.x, std::max(extent.y, extent.z)) * 1.01f, 1.0e-6f);
  nodes_.push_back(root);
}

bool IrradianceCache::error(const IrradianceRecord& r, const glm::vec3& x, const glm::vec3& n, float& eps) const {
  if (!(r.radius > 0.0f)) return false;
  const glm::vec3 d = x - r.position;
  if (glm::dot(d, 0.5f * (n + r.normal)) < -kFrontTolerance * r.radius) return false;
  eps = glm::length(d) / r.radius + std::sqrt(std::max(0.0f, 1.0f - glm::dot(n, r.normal)));
  return eps < accuracy_;
}

// Calls fn(record index) for every record in a node whose cube, grown by half its edge plus
// `grow`, contains x: every record whose reach (plus grow) can contain x.
template <class Fn>
void IrradianceCache::visit(const glm::vec3& x, float grow, Fn&& fn) const {
  std::int32_t stack[8 * kMaxDepth + 8];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::int32_t index = stack[--top];
    const Node& node = nodes_[std::size_t(index)];
    const glm::vec3 d = glm::abs(x - node.centre);
    const float reach = 2.0f * node.half + grow;  // half + the largest reach (half) + grow
    // The root also holds records too large for it: always visited.
    if (index != 0 && (d.x > reach || d.y > reach || d.z > reach)) continue;
    for (std::uint32_t i : node.records) fn(i);
    for (std::int32_t c : node.child)
      if (c >= 0) stack[top++] = c;
  }
}

void IrradianceCache::insert(IrradianceRecord record) {
  // Neighbour clamping against every record whose reach overlaps the new one's.
  const float reach = accuracy_ * record.radius;
  visit(record.position, reach, [&](std::uint32_t j) {
    IrradianceRecord& other = records_[j];
    const float d = glm::length(other.position - record.position);
    if (d >= reach + accuracy_ * other.radius) return;
    record.radius = std::min(record.radius, other.radius + d);
    other.radius = std::min(other.radius, record.radius + d);
  });
  // The node: descend while the child's edge still holds the record's reach twice.
  const float need = 2.0f * accuracy_ * record.radius;
  std::int32_t at = 0;
  for (int depth = 0; depth < kMaxDepth; ++depth) {
    const Node& node = nodes_[std::size_t(at)];
    if (node.half < need) break;  // the child's edge (= node.half) would be too small
    const glm::vec3 c = node.centre;
    const int octant = (record.position.x > c.x ? 1 : 0) | (record.position.y > c.y ? 2 : 0) | (record.position.z > c.z ? 4 : 0);
    if (node.child[octant] < 0) {
      Node child;
      child.half = 0.5f * node.half;
      child.centre = c + child.half * glm::vec3(octant & 1 ? 1.0f : -1.0f, octant & 2 ? 1.0f : -1.0f, octant & 4 ? 1.0f : -1.0f);
      nodes_.push_back(child);
      nodes_[std::size_t(at)].child[octant] = std::int32_t(nodes_.size() - 1);
    }
    at = nodes_[std::size_t(at)].child[octant];
  }
  nodes_[std::size_t(at)].records.push_back(std::uint32_t(records_.size()));
  records_.push_back(record);
}

bool IrradianceCache::lookup(const glm::vec3& x, const glm::vec3& n, glm::vec3& irradiance) const {
  // Summed in record order whatever the octree's visiting order: sort the usable ones first.
  float weights = 0.0f;
  glm::vec3 sum(0.0f);
  std::uint32_t found[64];
  int count = 0;
  visit(x, 0.0f, [&](std::uint32_t i) {
    float eps;
    if (count < 64 && error(records_[i], x, n, eps)) found[count++] = i;
  });
  if (count == 0) return false;
  std::sort(found, found + count);
  for (int k = 0; k < count; ++k) {
    const IrradianceRecord& r = records_[found[k]];
    float eps;
    error(r, x, n, eps);
    const float w = std::min(kMaxWeight, 1.0f / std::max(eps, 1.0f / kMaxWeight) - 1.0f / accuracy_);
    if (!(w > 0.0f)) continue;
    const glm::vec3 rotation = glm::cross(r.normal, n);
    const glm::vec3 offset = x - r.position;
    glm::vec3 e;
    for (int c = 0; c < 3; ++c)
      e[c] = std::max(0.0f, r.irradiance[c] + glm::dot(rotation, r.rotationGradient[c]) +
                                glm::dot(offset, r.translationGradient[c]));
    sum += w * e;
    weights += w;
  }
  if (!(weights > 0.0f)) return false;
  irradiance = sum / weights;
  return true;
}

bool IrradianceCache::covers(const glm::vec3& x, const glm::vec3& n) const {
  bool any = false;
  visit(x, 0.0f, [&](std::uint32_t i) {
    float eps;
    if (!any && error(records_[i], x, n, eps) && eps < accuracy_) any = true;
  });
  return any;
}

}  // namespace pr::pm
