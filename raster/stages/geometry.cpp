// Geometry stage: transform, near-plane (and, rarely, guard-band) clipping in homogeneous
// space, snapping to 24.8 fixed point and back-face culling. Runs on whichever PE holds a
// triangle batch (sort-middle, sort-last) or on a region owner (sort-first); it reads the scene
// (replicated, read-only) and writes only its output vector.
#include "raster/stages/geometry.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/util/error.h"
#include "common/util/limits.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {

namespace {

// A polygon vertex during clipping: everything here is affine in world space, so the
// intersection with a clip plane is a linear interpolation of all of it.
struct ClipVertex {
  glm::vec4 clip;
  float viewDepth;
  glm::vec2 bary;
};

enum Plane : int { kNear, kLeft, kRight, kBottom, kTop, kPlaneCount };

// Signed distances (>= 0 inside) to the clip planes.
float planeDistance(const FrameView& view, const ClipVertex& v, int plane) {
  switch (plane) {
    // Perspective: w is the view-axis distance, so the near plane is w = znear. Orthographic:
    // w = 1 and the near plane is the view-axis distance znear.
    case kNear: return (view.perspective ? v.clip.w : v.viewDepth) - view.znear;
    case kLeft: return v.clip.x + view.guardX * v.clip.w;
    case kRight: return view.guardX * v.clip.w - v.clip.x;
    case kBottom: return v.clip.y + view.guardY * v.clip.w;
    case kTop: return view.guardY * v.clip.w - v.clip.y;
  }
  return 0.0f;
}

// The point where edge (in, out) crosses the plane. Always interpolated from the inside vertex
// towards the outside one, so the two triangles sharing an edge produce the very same vertex
// (no cracks along clipped shared edges). The result is then put exactly on the plane: far
// outside vertices (w = -1e6 behind the camera) would otherwise leave rounding errors larger
// than znear and a vertex with w <= 0.
// The interpolation starts from the nearer endpoint in parameter: from `in` with
// t = dIn / (dIn - dOut) when t <= 1/2, else from `out` with 1 - t = dOut / (dOut - dIn)
// computed directly. in + t (out - in) with t rounded to 1 would lose `out` entirely when the
// endpoints differ by orders of magnitude (w = 9e6 against w = 0.01 gives w = 0).
ClipVertex intersectEdge(const FrameView& view, const ClipVertex& in, float dIn, const ClipVertex& out,
                         float dOut, int plane) {
  ClipVertex v;
  if (dIn <= -dOut) {
    float t = dIn / (dIn - dOut);
    v.clip = in.clip + t * (out.clip - in.clip);
    v.viewDepth = in.viewDepth + t * (out.viewDepth - in.viewDepth);
    v.bary = in.bary + t * (out.bary - in.bary);
  } else {
    float s = dOut / (dOut - dIn);
    v.clip = out.clip + s * (in.clip - out.clip);
    v.viewDepth = out.viewDepth + s * (in.viewDepth - out.viewDepth);
    v.bary = out.bary + s * (in.bary - out.bary);
  }
  switch (plane) {
    case kNear:
      if (view.perspective) v.clip.w = view.znear;
      else v.viewDepth = view.znear;
      break;
    case kLeft: v.clip.x = -view.guardX * v.clip.w; break;
    case kRight: v.clip.x = view.guardX * v.clip.w; break;
    case kBottom: v.clip.y = -view.guardY * v.clip.w; break;
    case kTop: v.clip.y = view.guardY * v.clip.w; break;
  }
  return v;
}

// Room for clipping: a convex polygon gains at most one vertex per plane (3 + 5 = 8), but
// vertices moved onto earlier planes can make it non-convex by a rounding error, and then a
// plane may cut it more than twice. The buffers leave room for that; assembleTriangle drops
// the (pathological) result when it exceeds kMaxPolygonVertices.
constexpr int kClipBufferVertices = 2 * kMaxPolygonVertices;

// Sutherland-Hodgman against one plane; n vertices in, the count out (at most
// kClipBufferVertices; -1 if it would not fit).
int clipPolygon(const FrameView& view, const ClipVertex* in, int n, ClipVertex* out, int plane) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % n];
    float da = planeDistance(view, a, plane);
    float db = planeDistance(view, b, plane);
    if (m + 2 > kClipBufferVertices) return -1;
    if (da >= 0.0f) out[m++] = a;
    if ((da >= 0.0f) != (db >= 0.0f)) {
      out[m++] = da >= 0.0f ? intersectEdge(view, a, da, b, db, plane) : intersectEdge(view, b, db, a, da, plane);
    }
  }
  return m;
}

struct SnappedVertex {
  int32_t x, y;
  float depth, invW;
  glm::vec2 bary;
};

// Round half away from zero with one truncating conversion (std::nearbyint is a library call
// on baseline x86-64); |v| <= kLimit < 2^31, so the conversion cannot overflow.
inline int32_t roundToFixed(double v) { return static_cast<int32_t>(v + (v >= 0.0 ? 0.5 : -0.5)); }

// Perspective division and viewport transform, snapped to 24.8 fixed point (round to nearest).
// Clipping guarantees w > 0 and |x/w| <= guardX; the clamp only absorbs rounding at the guard.
// Kept out of line so that every vertex, cached or clipped, goes through the same instruction
// sequence: a vertex shared by two triangles must snap to the same position (watertightness).
[[gnu::noinline]] void snap(const FrameView& view, glm::vec4 clip, float viewDepth, SnappedVertex& s) {
  constexpr double kLimit = (kGuardBandPx + kMaxImageSidePx) * kSubpixelScale;
  double invW = 1.0 / double(clip.w);
  double sx = (0.5 + 0.5 * double(clip.x) * invW) * view.width * kSubpixelScale;
  double sy = (0.5 - 0.5 * double(clip.y) * invW) * view.height * kSubpixelScale;
  s.x = roundToFixed(std::clamp(sx, -kLimit, kLimit));
  s.y = roundToFixed(std::clamp(sy, -kLimit, kLimit));
  s.invW = static_cast<float>(invW);
  s.depth = view.perspective ? -s.invW : viewDepth;
}

// Twice the signed area of a snapped triangle, positive for a front face (counter-clockwise
// as seen on screen): the edge function E_0 of setup.h at the first vertex.
int64_t signedArea2(const SnappedVertex& a, const SnappedVertex& b, const SnappedVertex& c) {
  return int64_t(c.y - b.y) * int64_t(a.x - b.x) - int64_t(c.x - b.x) * int64_t(a.y - b.y);
}

uint32_t outcode(const FrameView& view, const ClipVertex& v, bool guard) {
  uint32_t code = 0;
  if (planeDistance(view, v, kNear) < 0.0f) code |= 1u << kNear;
  float gx = guard ? view.guardX : 1.0f;
  float gy = guard ? view.guardY : 1.0f;
  if (v.clip.x < -gx * v.clip.w) code |= 1u << kLeft;
  if (v.clip.x > gx * v.clip.w) code |= 1u << kRight;
  if (v.clip.y < -gy * v.clip.w) code |= 1u << kBottom;
  if (v.clip.y > gy * v.clip.w) code |= 1u << kTop;
  return code;
}

// The vertex stage: one scene vertex transformed, classified against the frustum and the guard
// band, and snapped when no clipping can move it. Computed once per vertex of a batch.
struct PreparedVertex {
  glm::vec4 clip;
  float viewDepth;
  uint32_t viewportCode, guardCode;
  bool finite;            // false for NaN/inf input or a transform that overflowed float
  SnappedVertex snapped;  // valid when guardCode == 0
};

// Out of line for the same reason as snap(): identical transforms for shared vertices.
[[gnu::noinline]] void prepareVertex(const FrameView& view, glm::vec3 p, PreparedVertex& out) {
  glm::vec4 hp(p, 1.0f);
  ClipVertex v{view.viewProjection * hp, glm::dot(view.viewDepthRow, hp), glm::vec2(0.0f)};
  out.clip = v.clip;
  out.viewDepth = v.viewDepth;
  out.finite = std::isfinite(v.clip.x) && std::isfinite(v.clip.y) && std::isfinite(v.clip.z) &&
               std::isfinite(v.clip.w) && std::isfinite(v.viewDepth);
  if (!out.finite) {
    out.viewportCode = out.guardCode = 0;
    return;
  }
  out.viewportCode = outcode(view, v, false);
  out.guardCode = outcode(view, v, true);
  if (out.guardCode == 0) snap(view, v.clip, v.viewDepth, out.snapped);
}

// Triangle assembly from prepared vertices: trivial reject, clipping when a vertex lies
// behind the near plane or beyond the guard band, facing, fan of screen triangles.
int assembleTriangle(const scene::Scene& scene, const FrameView& view, uint32_t index, const PreparedVertex* pv[3],
                     ScreenTriangle* out, GeometryCounters& c) {
  ++c.trianglesIn;
  // A non-finite corner has no meaningful position on screen: the triangle is dropped whole
  // (the loader rejects such files; this keeps NaN out of the fixed-point conversion anyway).
  if (!(pv[0]->finite && pv[1]->finite && pv[2]->finite)) {
    ++c.culledDegenerate;
    return 0;
  }
  // Trivial reject: all three outside one viewport or near plane (the triangle is the convex
  // hull of its clip-space vertices, so it cannot reach into the frustum).
  if (pv[0]->viewportCode & pv[1]->viewportCode & pv[2]->viewportCode) {
    ++c.culledOutside;
    return 0;
  }
  static constexpr glm::vec2 kCorner[3] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
  SnappedVertex s[kMaxPolygonVertices];
  int n = 3;
  uint32_t clipMask = pv[0]->guardCode | pv[1]->guardCode | pv[2]->guardCode;
  if (clipMask == 0) {
    for (int k = 0; k < 3; ++k) {
      s[k] = pv[k]->snapped;
      s[k].bary = kCorner[k];
    }
  } else {
    // Clip only against the planes some vertex violates: the near plane first, so that w > 0
    // holds before the guard planes (which pass through the eye) are tested.
    ++c.clipped;
    ClipVertex poly[2][kClipBufferVertices];
    for (int k = 0; k < 3; ++k) poly[0][k] = ClipVertex{pv[k]->clip, pv[k]->viewDepth, kCorner[k]};
    int cur = 0;
    for (int plane = 0; plane < kPlaneCount && n >= 3 && n <= kMaxPolygonVertices; ++plane) {
      if (!(clipMask & (1u << plane))) continue;
      n = clipPolygon(view, poly[cur], n, poly[cur ^ 1], plane);
      cur ^= 1;
    }
    if (n < 0 || n > kMaxPolygonVertices) {
      // Only reachable through rounding at vertices already on a clip plane: a sliver.
      ++c.culledDegenerate;
      return 0;
    }
    if (n < 3) {
      ++c.culledOutside;
      return 0;
    }
    for (int k = 0; k < n; ++k) {
      // Clipping keeps w >= znear up to rounding; a polygon that still has a vertex at w <= 0
      // or a non-finite one is a numerical sliver and is dropped rather than divided by zero.
      const glm::vec4& cp = poly[cur][k].clip;
      if (!(cp.w > 0.0f) || !std::isfinite(cp.x) || !std::isfinite(cp.y) || !std::isfinite(poly[cur][k].viewDepth)) {
        ++c.culledDegenerate;
        return 0;
      }
      snap(view, poly[cur][k].clip, poly[cur][k].viewDepth, s[k]);
      s[k].bary = poly[cur][k].bary;
    }
  }

  // Facing of the whole (convex) polygon, from its snapped area: the sum of its fan.
  int64_t area2 = 0;
  for (int k = 1; k + 1 < n; ++k) area2 += signedArea2(s[0], s[k], s[k + 1]);
  if (area2 == 0) {
    ++c.culledDegenerate;
    return 0;
  }
  bool backFacing = area2 < 0;
  if (backFacing) {
    if (!scene.materials[scene.triangles[index].material].doubleSided) {
      ++c.culledBackFace;
      return 0;
    }
    // Seen from behind: reverse the winding so every piece has positive area.
    std::reverse(s + 1, s + n);
  }

  int count = 0;
  for (int k = 1; k + 1 < n; ++k) {
    // A piece whose snapped area is zero covers no sample; one flipped by snapping (a sliver
    // at a clip vertex) is dropped rather than drawn inside-out.
    if (n > 3 && signedArea2(s[0], s[k], s[k + 1]) <= 0) continue;
    ScreenTriangle& t = out[count++];
    const SnappedVertex* v[3] = {&s[0], &s[k], &s[k + 1]};
    for (int j = 0; j < 3; ++j) {
      t.x[j] = v[j]->x;
      t.y[j] = v[j]->y;
      t.depth[j] = v[j]->depth;
      t.invW[j] = v[j]->invW;
      t.bary[j] = v[j]->bary;
    }
    t.primitive = index;
    t.sub = static_cast<uint8_t>(k - 1);
    t.backFacing = backFacing ? 1 : 0;
  }
  if (count == 0) ++c.culledDegenerate;
  c.screenTrianglesOut += static_cast<uint64_t>(count);
  return count;
}

}  // namespace

GeometryCounters& GeometryCounters::operator+=(const GeometryCounters& o) {
  trianglesIn += o.trianglesIn;
  culledOutside += o.culledOutside;
  culledBackFace += o.culledBackFace;
  culledDegenerate += o.culledDegenerate;
  clipped += o.clipped;
  screenTrianglesOut += o.screenTrianglesOut;
  return *this;
}

FrameView makeFrameView(const scene::Camera& camera, int width, int height) {
  if (width < 1 || width > kMaxImageSidePx || height < 1 || height > kMaxImageSidePx) {
    throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is outside [1, " + std::to_string(kMaxImageSidePx) + "] per side");
  }
  FrameView view;
  view.width = width;
  view.height = height;
  glm::mat4 v = camera.view();
  view.viewProjection = camera.projectionMatrix(float(width) / float(height)) * v;
  // Row 2 of the view matrix gives z_view; the camera looks down -z.
  view.viewDepthRow = -glm::vec4(v[0][2], v[1][2], v[2][2], v[3][2]);
  // A non-positive znear would put the near plane through the eye (w = 0): clamp to a tiny
  // positive distance, which keeps 1/w finite.
  view.znear = std::max(camera.znear, 1e-20f);
  view.perspective = camera.projection == scene::Projection::Perspective;
  view.eye = camera.position();
  view.forward = -glm::normalize(glm::vec3(camera.cameraToWorld[2]));
  // |x_ndc| <= 2G/W keeps the screen x within G pixels of the screen centre.
  view.guardX = float(2.0 * kGuardBandPx / width);
  view.guardY = float(2.0 * kGuardBandPx / height);
  return view;
}

int processTriangle(const scene::Scene& scene, const FrameView& view, uint32_t index,
                    ScreenTriangle* out, GeometryCounters* counters) {
  GeometryCounters local;
  PreparedVertex v[3];
  const PreparedVertex* pv[3] = {&v[0], &v[1], &v[2]};
  for (int k = 0; k < 3; ++k) prepareVertex(view, scene.positions[scene.triangles[index].v[k]], v[k]);
  return assembleTriangle(scene, view, index, pv, out, counters ? *counters : local);
}

void checkRasterLimits(std::string_view where, size_t triangles) {
  checkCountLimit(where, "triangles", triangles, kMaxPrimitives,
                  "the rasterizers' depth key orders primitives by a 29-bit id");
}

void processTriangles(const scene::Scene& scene, const FrameView& view, uint32_t first, uint32_t count,
                      std::vector<ScreenTriangle>& out, GeometryCounters* counters) {
  PR_CHECK(uint64_t(first) + count <= scene.triangles.size(), "triangle batch outside the scene");
  PR_CHECK(scene.triangles.size() <= kMaxPrimitives,
           "scene has more triangles than the depth key can order");
  if (count == 0) return;
  GeometryCounters local;
  GeometryCounters& c = counters ? *counters : local;
  const scene::Triangle* tris = scene.triangles.data() + first;
  // Mesh triangles of a batch reference a compact vertex range: prepare each vertex of the
  // range once (about 3x fewer transforms than per triangle corner). A scattered batch falls
  // back to per-corner preparation; both give the same bits (prepareVertex is one function).
  uint32_t lo = tris[0].v[0], hi = lo;
  for (uint32_t i = 0; i < count; ++i) {
    for (uint32_t k : tris[i].v) {
      lo = std::min(lo, k);
      hi = std::max(hi, k);
    }
  }
  ScreenTriangle pieces[kMaxSubTriangles];
  const uint64_t range = uint64_t(hi) - lo + 1;
  if (range > 2 * uint64_t(count) + 64) {
    for (uint32_t i = 0; i < count; ++i) {
      int n = processTriangle(scene, view, first + i, pieces, &c);
      for (int k = 0; k < n; ++k) out.push_back(pieces[k]);
    }
    return;
  }
  // Per-thread scratch: the PE running this batch reuses its own buffer between batches.
  thread_local std::vector<PreparedVertex> prepared;
  prepared.resize(range);
  for (uint64_t k = 0; k < range; ++k) prepareVertex(view, scene.positions[lo + k], prepared[k]);
  for (uint32_t i = 0; i < count; ++i) {
    const PreparedVertex* pv[3] = {&prepared[tris[i].v[0] - lo], &prepared[tris[i].v[1] - lo], &prepared[tris[i].v[2] - lo]};
    int n = assembleTriangle(scene, view, first + i, pv, pieces, c);
    for (int k = 0; k < n; ++k) out.push_back(pieces[k]);
  }
}

}  // namespace pr::raster
