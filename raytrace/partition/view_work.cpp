// The projection, clipping and cutting of view_work.h.
#include "raytrace/partition/view_work.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pr::rt {
namespace {

// Cuts of a piece in four before it is taken as it is (or dropped, when it is still far larger
// than the image or crosses the camera plane): 4^24 pieces of a triangle at most, though only
// the pieces near the eye are cut that often.
constexpr int kMaxCutDepth = 24;

struct Projector {
  glm::mat4 view;
  bool orthographic = false;
  float sx = 1.0f, sy = 1.0f;  // view-space units per half image (at unit depth for perspective)
  float znear = 0.0f;
  float width = 0.0f, height = 0.0f;

  // False when the point is not in front of the camera.
  bool toPixels(glm::vec3 world, glm::vec2& out) const {
    const glm::vec3 q = glm::vec3(view * glm::vec4(world, 1.0f));
    if (!(-q.z > znear)) return false;
    const float depth = orthographic ? 1.0f : -q.z;
    const float x = q.x / (depth * sx), y = q.y / (depth * sy);  // in [-1, 1] on the image
    out = {0.5f * (x + 1.0f) * width, 0.5f * (1.0f - y) * height};
    return std::isfinite(out.x) && std::isfinite(out.y);
  }
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

void addPiece(const Projector& pr, glm::vec3 a, glm::vec3 b, glm::vec3 c, int depth, std::vector<WorkPoint>& out) {
  glm::vec2 pa, pb, pc;
  const bool ina = pr.toPixels(a, pa), inb = pr.toPixels(b, pb), inc = pr.toPixels(c, pc);
  if (ina && inb && inc) {
    // Wholly outside one side of the image: nothing of it is seen.
    const glm::vec2 lo = glm::min(pa, glm::min(pb, pc)), hi = glm::max(pa, glm::max(pb, pc));
    if (hi.x <= 0.0f || hi.y <= 0.0f || lo.x >= pr.width || lo.y >= pr.height) return;
    // Far larger than the image (near the eye): clipping it in 2D would lose the image's
    // pixels in the rounding of its far corners, so it is cut first.
    const float huge = 4.0f * (pr.width + pr.height);
    if (hi.x - lo.x <= huge && hi.y - lo.y <= huge) {
      const float pixels = clippedArea(pa, pb, pc, pr.width, pr.height);
      if (pixels <= 0.0f) return;
      if (pixels <= kViewWorkPiecePixels || depth >= kMaxCutDepth) {
        out.push_back({(a + b + c) * (1.0f / 3.0f), pixels});
        return;
      }
    }
  } else if (!ina && !inb && !inc) {
    // Every corner behind the camera plane: so is the whole (convex) piece.
    const glm::vec3 qa = glm::vec3(pr.view * glm::vec4(a, 1.0f)), qb = glm::vec3(pr.view * glm::vec4(b, 1.0f)),
                    qc = glm::vec3(pr.view * glm::vec4(c, 1.0f));
    if (-qa.z <= pr.znear && -qb.z <= pr.znear && -qc.z <= pr.znear) return;
  }
  if (depth >= kMaxCutDepth) return;  // still crossing the camera plane: dropped
  const glm::vec3 ab = 0.5f * (a + b), bc = 0.5f * (b + c), ca = 0.5f * (c + a);
  addPiece(pr, a, ab, ca, depth + 1, out);
  addPiece(pr, ab, b, bc, depth + 1, out);
  addPiece(pr, ca, bc, c, depth + 1, out);
  addPiece(pr, ab, bc, ca, depth + 1, out);
}

}  // namespace

std::vector<WorkPoint> viewWork(const scene::Scene& scene, const scene::Camera& camera, int width, int height) {
  Projector pr;
  pr.view = camera.view();
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
  // most pixels are.
  const float plane = -(pr.znear + 1e-6f + 1e-3f * pr.znear);  // view-space z just in front of the eye
  std::vector<WorkPoint> out;
  for (const scene::Triangle& t : scene.triangles) {
    const glm::vec3 p[3] = {scene.positions[t.v[0]], scene.positions[t.v[1]], scene.positions[t.v[2]]};
    float z[3];
    int front = 0;
    for (int i = 0; i < 3; ++i) {
      z[i] = (pr.view * glm::vec4(p[i], 1.0f)).z;
      front += z[i] < plane ? 1 : 0;
    }
    if (front == 3 || front == 0) {
      if (front == 3) addPiece(pr, p[0], p[1], p[2], 0, out);
      continue;
    }
    glm::vec3 poly[4];
    int n = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (z[i] < plane) poly[n++] = p[i];
      if ((z[i] < plane) != (z[j] < plane)) poly[n++] = p[i] + (p[j] - p[i]) * ((plane - z[i]) / (z[j] - z[i]));
    }
    for (int i = 1; i + 1 < n; ++i) addPiece(pr, poly[0], poly[i], poly[i + 1], 0, out);
  }
  return out;
}

}  // namespace pr::rt
