// The watertight ray-triangle test of triangle.h on a whole BVH leaf at once: up to four
// triangles, one per SSE lane. Every lane performs the scalar test's float operations in the
// same order (SSE arithmetic rounds as scalar float arithmetic does, and nothing is fused), so
// each lane's hit, t, u and v are bit-identical to intersectTriangle<Kz>'s; a lane whose edge
// function comes out exactly 0 is handed to the scalar test, which redoes it in double.
#pragma once

#include <cstdint>

#include <emmintrin.h>  // SSE2: part of every x86-64 target

#include "raytrace/core/bvh.h"
#include "raytrace/core/triangle.h"

namespace pr::rt {

// Hits of the first `count` triangles of a leaf block (1 <= count <= 4) for t in [tMin, tMax]:
// bit i of the result is set when triangle i is hit, and then t[i], u[i], v[i] hold what
// intersectTriangle gives for it. Always inlined: called out of line from the AVX2 traversal
// (bvh_traverse_lanes.inc), each call cleared the upper vector state and made the caller keep
// its ray constants in memory across it; inlined there it runs as VEX code (no FMA: the
// same operations, the same bits) with the traversal's registers intact.
template <int Kz>
__attribute__((always_inline)) inline int intersectLeaf(const RayShear& s, const BvhLeafBlock& block, uint32_t count,
                                                        float tMin, float tMax, float (&t)[kLeafLanes],
                                                        float (&u)[kLeafLanes], float (&v)[kLeafLanes]) {
  constexpr int Kx = (Kz + 1) % 3, Ky = (Kx + 1) % 3;
  // Rows x, y, z of p0, p1 and p2 over the lanes.
  __m128 p[3][3];
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) p[k][a] = _mm_load_ps(block.p[k][a]);
  const __m128 o[3] = {_mm_set1_ps(s.origin.x), _mm_set1_ps(s.origin.y), _mm_set1_ps(s.origin.z)};
  const __m128 sx = _mm_set1_ps(s.sx), sy = _mm_set1_ps(s.sy);
  // Vertices relative to the origin (a, b, c) and sheared (triangle.h, eq. 1-3).
  __m128 rel[3][3], shx[3], shy[3];
  for (int k = 0; k < 3; ++k) {
    for (int axisIndex = 0; axisIndex < 3; ++axisIndex) rel[k][axisIndex] = _mm_sub_ps(p[k][axisIndex], o[axisIndex]);
    shx[k] = _mm_sub_ps(rel[k][Kx], _mm_mul_ps(sx, rel[k][Kz]));
    shy[k] = _mm_sub_ps(rel[k][Ky], _mm_mul_ps(sy, rel[k][Kz]));
  }
  const __m128 eu = _mm_sub_ps(_mm_mul_ps(shx[2], shy[1]), _mm_mul_ps(shy[2], shx[1]));
  const __m128 ev = _mm_sub_ps(_mm_mul_ps(shx[0], shy[2]), _mm_mul_ps(shy[0], shx[2]));
  const __m128 ew = _mm_sub_ps(_mm_mul_ps(shx[1], shy[0]), _mm_mul_ps(shy[1], shx[0]));
  const __m128 zero = _mm_setzero_ps();
  const int valid = (1 << count) - 1;
  const int exactZero =
      _mm_movemask_ps(_mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(eu, zero), _mm_cmpeq_ps(ev, zero)), _mm_cmpeq_ps(ew, zero))) & valid;
  const __m128 negative = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(eu, zero), _mm_cmplt_ps(ev, zero)), _mm_cmplt_ps(ew, zero));
  const __m128 positive = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(eu, zero), _mm_cmpgt_ps(ev, zero)), _mm_cmpgt_ps(ew, zero));
  int mask = valid & ~exactZero & ~_mm_movemask_ps(_mm_and_ps(negative, positive));
  if (mask != 0) {
    const __m128 det = _mm_add_ps(_mm_add_ps(eu, ev), ew);
    // The plane-equation distance of triangle.h: n = (p1 - p0) x (p2 - p0), t = n.a / n.d.
    __m128 e1[3], e2[3];
    for (int axisIndex = 0; axisIndex < 3; ++axisIndex) {
      e1[axisIndex] = _mm_sub_ps(p[1][axisIndex], p[0][axisIndex]);
      e2[axisIndex] = _mm_sub_ps(p[2][axisIndex], p[0][axisIndex]);
    }
    const __m128 nx = _mm_sub_ps(_mm_mul_ps(e1[1], e2[2]), _mm_mul_ps(e2[1], e1[2]));
    const __m128 ny = _mm_sub_ps(_mm_mul_ps(e1[2], e2[0]), _mm_mul_ps(e2[2], e1[0]));
    const __m128 nz = _mm_sub_ps(_mm_mul_ps(e1[0], e2[1]), _mm_mul_ps(e2[0], e1[1]));
    // glm::dot's order: (x x' + y y') + z z'.
    const auto dotN = [&](__m128 x, __m128 y, __m128 z) {
      return _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, x), _mm_mul_ps(ny, y)), _mm_mul_ps(nz, z));
    };
    const __m128 dot = dotN(_mm_set1_ps(s.direction.x), _mm_set1_ps(s.direction.y), _mm_set1_ps(s.direction.z));
    const __m128 numerator = dotN(rel[0][0], rel[0][1], rel[0][2]);
    const __m128 tv = _mm_div_ps(numerator, dot);
    const __m128 inRange = _mm_and_ps(_mm_cmpge_ps(tv, _mm_set1_ps(tMin)), _mm_cmple_ps(tv, _mm_set1_ps(tMax)));
    const __m128 rejected = _mm_or_ps(_mm_cmpeq_ps(det, zero), _mm_cmpeq_ps(dot, zero));
    mask &= _mm_movemask_ps(_mm_andnot_ps(rejected, inRange));
    _mm_storeu_ps(t, tv);
    _mm_storeu_ps(u, _mm_div_ps(ev, det));
    _mm_storeu_ps(v, _mm_div_ps(ew, det));
  }
  // Ties to an edge or a vertex: the scalar test's exact recomputation.
  for (int rest = exactZero; rest != 0; rest &= rest - 1) {
    const int lane = __builtin_ctz(unsigned(rest));
    TriangleHit th;
    if (intersectTriangle<Kz>(s, block.vertex(0, lane), block.vertex(1, lane), block.vertex(2, lane), tMin, tMax, th)) {
      mask |= 1 << lane;
      t[lane] = th.t;
      u[lane] = th.u;
      v[lane] = th.v;
    }
  }
  return mask;
}

}  // namespace pr::rt
