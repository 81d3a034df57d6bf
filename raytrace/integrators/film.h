// Film: where every tracer's shading results end up. Contributions are summed in fixed point
// (int64 per channel, value x 2^24) with relaxed atomic adds, so the sum is independent of the
// order in which PEs deliver them: integer addition is associative, float addition is not.
// That is what makes images bit-identical for every tracer, P and schedule. Film -> Image last.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "common/image/image.h"

namespace pr::rt {

class Film {
 public:
  // 2^24: resolves contributions down to 6e-8, well below an 8-bit or half-float step.
  static constexpr double kScale = 16777216.0;
  // A single contribution is clamped to this before conversion, so int64 sums of up to
  // 2^63 / (kMaxContribution * kScale) ~ 5e5 contributions per pixel and channel cannot overflow.
  static constexpr double kMaxContribution = 1.0e6;

  Film(int width, int height, int spp);

  int width() const { return width_; }
  int height() const { return height_; }
  int spp() const { return spp_; }

  // Adds radiance to a pixel (index y * width + x). Thread-safe; order-independent. A
  // non-finite or negative component is dropped (a guard; integrators do not produce them).
  void add(uint32_t pixel, const glm::vec3& radiance);

  // The fixed-point sum of one channel (for tests of order independence).
  int64_t raw(uint32_t pixel, int channel) const { return sums_[size_t(pixel) * 3 + channel].load(std::memory_order_relaxed); }

  // Mean radiance per pixel: sum / spp. Called after the render, from one thread.
  image::Image toImage() const;

 private:
  int width_, height_, spp_;
  std::unique_ptr<std::atomic<int64_t>[]> sums_;
};

}  // namespace pr::rt
