// Fixed-point film (see film.h). Written by any PE during a render, read once at the end.
#include "raytrace/integrators/film.h"

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

namespace pr::rt {

Film::Film(int width, int height, int spp) : width_(width), height_(height), spp_(spp) {
  PR_CHECK(width > 0 && height > 0 && spp > 0, "film needs a positive size and spp");
  const size_t n = size_t(width) * size_t(height) * 3;
  sums_ = std::make_unique<std::atomic<int64_t>[]>(n);
  for (size_t i = 0; i < n; ++i) sums_[i].store(0, std::memory_order_relaxed);
}

void Film::add(uint32_t pixel, const glm::vec3& radiance) {
  PR_DCHECK(pixel < uint32_t(width_) * uint32_t(height_), "pixel outside the film");
  for (int c = 0; c < 3; ++c) {
    const float v = radiance[c];
    if (!(v > 0.0f) || !std::isfinite(v)) continue;  // also drops NaN
    const double clamped = std::min(double(v), kMaxContribution);
    const int64_t fixed = std::llround(clamped * kScale);
    if (fixed != 0) sums_[size_t(pixel) * 3 + c].fetch_add(fixed, std::memory_order_relaxed);
  }
}

image::Image Film::toImage() const {
  image::Image image(width_, height_);
  const double norm = 1.0 / (kScale * double(spp_));
  for (size_t p = 0; p < image.pixels.size(); ++p)
    for (int c = 0; c < 3; ++c)
      image.pixels[p][c] = float(double(sums_[p * 3 + c].load(std::memory_order_relaxed)) * norm);
  return image;
}

}  // namespace pr::rt
