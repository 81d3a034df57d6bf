// A precomputed function of two variables in [0, 1] (BRDF albedo tables): values on an
// N x N grid, row = y, column = x, read bilinearly with the arguments clamped to [0, 1].
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

namespace pr {

template <class T, int N>
struct UnitTable {
  std::array<T, size_t(N) * size_t(N)> values{};

  T& at(int row, int column) { return values[size_t(row) * N + size_t(column)]; }
  const T& at(int row, int column) const { return values[size_t(row) * N + size_t(column)]; }
  // The grid coordinate of sample i: i / (N - 1).
  static float coordinate(int i) { return float(i) / float(N - 1); }

  T lookup(float x01, float y01) const {
    const float x = std::clamp(x01, 0.0f, 1.0f) * float(N - 1), y = std::clamp(y01, 0.0f, 1.0f) * float(N - 1);
    const int x0 = std::min(int(x), N - 2), y0 = std::min(int(y), N - 2);
    const float fx = x - float(x0), fy = y - float(y0);
    const T lo = at(y0, x0) * (1.0f - fx) + at(y0, x0 + 1) * fx;
    const T hi = at(y0 + 1, x0) * (1.0f - fx) + at(y0 + 1, x0 + 1) * fx;
    return lo * (1.0f - fy) + hi * fy;
  }
};

}  // namespace pr
