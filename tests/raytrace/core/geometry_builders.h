// Scenes built in code for the ray tracing core tests: random triangle soups, tessellated
// closed boxes whose seams share bit-identical vertices, height fields. Each returns a plain
// pr::scene::Scene (positions, triangles, one material), as the glTF loader would fill it.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"

namespace pr::test {

inline scene::Scene emptyScene() {
  scene::Scene s;
  s.materials.resize(1);
  return s;
}

inline void addTriangle(scene::Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material = 0) {
  const auto base = static_cast<uint32_t>(s.positions.size());
  s.positions.insert(s.positions.end(), {a, b, c});
  s.triangles.push_back({{base, base + 1, base + 2}, material});
  s.bounds.extend(a);
  s.bounds.extend(b);
  s.bounds.extend(c);
}

// Appends src's vertices and triangles to s (its indices moved past s's vertices), each
// triangle with `material`.
inline void appendTriangles(scene::Scene& s, const scene::Scene& src, uint32_t material = 0) {
  const auto base = static_cast<uint32_t>(s.positions.size());
  s.positions.insert(s.positions.end(), src.positions.begin(), src.positions.end());
  for (scene::Triangle t : src.triangles) {
    for (uint32_t& v : t.v) v += base;
    t.material = material;
    s.triangles.push_back(t);
  }
  s.bounds.extend(src.bounds);
}

// `count` random triangles with vertices in centre +- scale (edges up to ~0.3 scale).
inline scene::Scene randomSoup(int count, float scale = 1.0f, glm::vec3 centre = glm::vec3(0.0f),
                               uint32_t seed = 1) {
  scene::Scene s = emptyScene();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), edge(-0.3f, 0.3f);
  for (int i = 0; i < count; ++i) {
    const glm::vec3 a(pos(rng), pos(rng), pos(rng));
    const glm::vec3 b = a + glm::vec3(edge(rng), edge(rng), edge(rng));
    const glm::vec3 c = a + glm::vec3(edge(rng), edge(rng), edge(rng));
    addTriangle(s, centre + scale * a, centre + scale * b, centre + scale * c);
  }
  return s;
}

// Coordinates lo + (hi - lo) i / n, computed once per axis so that every face of a box uses
// bit-identical values along its seams (a watertight mesh, as a glTF file with shared
// vertices would give).
inline std::vector<float> gridCoordinates(float lo, float hi, int n) {
  std::vector<float> c(n + 1);
  for (int i = 0; i <= n; ++i) c[i] = i == n ? hi : lo + (hi - lo) * (float(i) / float(n));
  return c;
}

// A closed axis-aligned box, each face an n x n grid of quads (two triangles each), wound
// counter-clockwise seen from outside, so geometric normals point out.
inline scene::Scene closedBox(glm::vec3 lo, glm::vec3 hi, int n) {
  scene::Scene s = emptyScene();
  const std::array<std::vector<float>, 3> coords = {gridCoordinates(lo.x, hi.x, n), gridCoordinates(lo.y, hi.y, n),
                                                    gridCoordinates(lo.z, hi.z, n)};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      // (u, v, axis) is a right-handed frame: cross(u, v) = +axis. The low side swaps u and v
      // so its normal points to -axis.
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      if (side == 0) std::swap(u, v);
      const float w = side == 0 ? lo[axis] : hi[axis];
      const auto base = static_cast<uint32_t>(s.positions.size());
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
          glm::vec3 p;
          p[axis] = w;
          p[u] = coords[u][i];
          p[v] = coords[v][j];
          s.positions.push_back(p);
        }
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + (n + 1), d = c + 1;
          s.triangles.push_back({{a, b, d}, 0});
          s.triangles.push_back({{a, d, c}, 0});
        }
    }
  }
  s.bounds.extend(lo);
  s.bounds.extend(hi);
  return s;
}

// A height field over [0, size]^2 with n x n quads and pseudo-random heights in
// +-relief * size (z up).
inline scene::Scene heightField(int n, float size, float relief = 0.01f, uint32_t seed = 7) {
  scene::Scene s = emptyScene();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> h(-relief * size, relief * size);
  const std::vector<float> c = gridCoordinates(0.0f, size, n);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      s.positions.push_back({c[i], c[j], h(rng)});
      s.bounds.extend(s.positions.back());
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, cc = a + (n + 1), d = cc + 1;
      s.triangles.push_back({{a, b, d}, 0});
      s.triangles.push_back({{a, d, cc}, 0});
    }
  return s;
}

inline glm::vec3 randomDirection(std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  for (;;) {
    const glm::vec3 d(g(rng), g(rng), g(rng));
    const float len = glm::length(d);
    if (len > 1e-3f) return d / len;
  }
}

}  // namespace pr::test
