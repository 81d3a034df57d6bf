// The projection, clipping and cutting of view_work.h.
#include "raytrace/partition/view_work.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pr::rt {
namespace {

// Cuts of a piece in four before it is taken as it is (or dropped, when it is still far larger
// than the image): only the pieces near the eye that overlap the image are cut that often.
constexpr int kMaxCutDepth = 24;

// Pieces are cut and projected in view space (the camera at the origin looking down -z), where
// the camera plane is a coordinate; their centroids go back to world space.
struct Projector {
  glm::mat4 toWorld;
  bool orthographic = false;
  float sx = 1.0f, sy = 1.0f;  // view-space units per half image (at unit depth for perspective)
  float znear = 0.0f;
  float width = 0.0f, height = 0.0f;

  // False when the projection of the (view-space) point is not in front or not finite.
  bool toPixels(glm::vec3 q, glm::vec2& out) const {
    if (!(-q.z > znear)) return false;
    const float depth = orthographic ? 1.0f : -q.z;
    const float x = q.x / (depth * sx), y = q.y / (depth * sy);  // in [-1, 1] on the image
    out = {0.5f * (x + 1.0f) * width, 0.5f * (1.0f - y) * height};
    return std::isfinite(out.x) && std::isfinite(out.y);
  }
  glm::vec3 world(glm::vec3 q) const { return glm::vec3(toWorld * glm::vec4(q, 1.0f)); }
};

// Area of triangle abc clipped to the image rectangle (Sutherland-Hodgman, then the shoelace).
float clippedArea(glm::vec2 a, glm::vec2 b, glm::vec2 c, float width, float height) {
  std::array<glm::vec2, 9> poly{a, b, c}, next{};
  int n = 3;
  auto clip = [&](int axis, float bound, bool keepBelow) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const glm::vec2 p = poly[size_t(i)], q = poly[size_t((i + 1) % n)];
      const bool pIn = keepBelow ? p[axis] <= bound : p[axis] >= bound;
      const bool qIn = keepBelow ? q[axis] <= bound : q[axis] >= bound;
      if (pIn) next[size_t(m++)] = p;
      if (pIn != qIn) next[size_t(m++)] = p + (q - p) * ((bound - p[axis]) / (q[axis] - p[axis]));
    }
    poly = next;
    n = m;
  };
  clip(0, 0.0f, false);
  clip(0, width, true);
  clip(1, 0.0f, false);
  clip(1, height, true);
  float twice = 0.0f;
  for (int i = 0; i < n; ++i) {
    const glm::vec2 p = poly[size_t(i)], q = poly[size_t((i + 1) % n)];
    twice += p.x * q.y - q.x * p.y;
  }
  return 0.5f * std::fabs(twice);
}

// A piece in front of the camera (viewWork clips triangles to the camera plane first, and the
// midpoints of points in front are in front).
void addPiece(const Projector& pr, glm::vec3 a, glm::vec3 b, glm::vec3 c, int depth, std::vector<WorkPoint>& out) {
  glm::vec2 pa, pb, pc;
  // A corner whose projection overflows: dropped (cutting it would not end).
  if (!pr.toPixels(a, pa) || !pr.toPixels(b, pb) || !pr.toPixels(c, pc)) return;
  // Wholly outside one side of the image: nothing of it is seen.
  const glm::vec2 lo = glm::min(pa, glm::min(pb, pc)), hi = glm::max(pa, glm::max(pb, pc));
  if (hi.x <= 0.0f || hi.y <= 0.0f || lo.x >= pr.width || lo.y >= pr.height) return;
  // Far larger than the image (near the eye): clipping it in 2D would lose the image's pixels
  // in the rounding of its far corners, so it is cut first.
  const float huge = 4.0f * (pr.width + pr.height);
  if (hi.x - lo.x <= huge && hi.y - lo.y <= huge) {
    const float pixels = clippedArea(pa, pb, pc, pr.width, pr.height);
    if (!(pixels > 0.0f)) return;
    if (pixels <= kViewWorkPiecePixels || depth >= kMaxCutDepth) {
      out.push_back({pr.world((a + b + c) * (1.0f / 3.0f)), pixels});
      return;
    }
  }
  if (depth >= kMaxCutDepth) return;  // still far larger than the image
  const glm::vec3 ab = 0.5f * (a + b), bc = 0.5f * (b + c), ca = 0.5f * (c + a);
  addPiece(pr, a, ab, ca, depth + 1, out);
  addPiece(pr, ab, b, bc, depth + 1, out);
  addPiece(pr, ca, bc, c, depth + 1, out);
  addPiece(pr, ab, bc, ca, depth + 1, out);
}

}  // namespace

std::vector<WorkPoint> viewWork(const scene::Scene& scene, const scene::Camera& camera, int width, int height) {
  Projector pr;
  pr.toWorld = camera.cameraToWorld;
  const glm::mat4 view = camera.view();
  pr.orthographic = camera.projection == scene::Projection::Orthographic;
  const float aspect = float(width) / float(height);
  const float tanY = pr.orthographic ? camera.ymag : std::tan(0.5f * camera.yfov);
  pr.sx = tanY * aspect;
  pr.sy = tanY;
  pr.znear = std::max(camera.znear, 0.0f);
  pr.width = float(width);
  pr.height = float(height);
  // A triangle through the camera plane is clipped to its part in front first (a fan of one or
  // two triangles): cutting alone would leave pieces across the plane near the eye, where the
  // most pixels are. The new corners get the clip plane's z exactly, in front of the eye.
  const float plane = -(pr.znear + 1e-6f + 1e-3f * pr.znear);

  // Each vertex once (a mesh's vertex is shared by about six triangles): in view space, and its
  // pixel position where it is in front and projects to finite pixels.
  struct Projected {
    glm::vec3 q;
    glm::vec2 pixel;
    bool finite, front, projects;
  };
  std::vector<Projected> vertices(scene.positions.size());
  for (size_t i = 0; i < scene.positions.size(); ++i) {
    const glm::vec3 p = scene.positions[i];
    Projected& v = vertices[i];
    v.finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    v.q = glm::vec3(view * glm::vec4(p, 1.0f));
    v.front = v.q.z < plane;
    v.projects = v.front && pr.toPixels(v.q, v.pixel);
  }

  std::vector<WorkPoint> out;
  for (const scene::Triangle& t : scene.triangles) {
    const Projected& a = vertices[t.v[0]];
    const Projected& b = vertices[t.v[1]];
    const Projected& c = vertices[t.v[2]];
    if (!(a.finite && b.finite && c.finite)) continue;  // never hit: the BVH makes it unhittable
    // The common case, a small triangle wholly inside the image: its area needs no clipping,
    // and its centroid is that of its world-space corners.
    if (a.projects && b.projects && c.projects) {
      const glm::vec2 lo = glm::min(a.pixel, glm::min(b.pixel, c.pixel)), hi = glm::max(a.pixel, glm::max(b.pixel, c.pixel));
      if (hi.x <= 0.0f || hi.y <= 0.0f || lo.x >= pr.width || lo.y >= pr.height) continue;  // outside one side
      if (lo.x >= 0.0f && lo.y >= 0.0f && hi.x <= pr.width && hi.y <= pr.height) {
        const glm::vec2 ab = b.pixel - a.pixel, ac = c.pixel - a.pixel;
        const float pixels = 0.5f * std::fabs(ab.x * ac.y - ab.y * ac.x);
        if (!(pixels > 0.0f)) continue;
        if (pixels <= kViewWorkPiecePixels) {
          const glm::vec3 centroid = (scene.positions[t.v[0]] + scene.positions[t.v[1]] + scene.positions[t.v[2]]) * (1.0f / 3.0f);
          out.push_back({centroid, pixels});
          continue;
        }
      }
    }
    const glm::vec3 q[3] = {a.q, b.q, c.q};
    const int front = int(a.front) + int(b.front) + int(c.front);
    if (front == 3 || front == 0) {
      if (front == 3) addPiece(pr, q[0], q[1], q[2], 0, out);
      continue;
    }
    glm::vec3 poly[4];
    int n = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (q[i].z < plane) poly[n++] = q[i];
      if ((q[i].z < plane) != (q[j].z < plane)) {
        glm::vec3 cut = q[i] + (q[j] - q[i]) * ((plane - q[i].z) / (q[j].z - q[i].z));
        cut.z = plane;
        poly[n++] = cut;
      }
    }
    for (int i = 1; i + 1 < n; ++i) addPiece(pr, poly[0], poly[i], poly[i + 1], 0, out);
  }
  return out;
}

}  // namespace pr::rt
