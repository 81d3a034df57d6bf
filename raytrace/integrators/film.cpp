// Fixed-point film (see film.h). Written by any PE during a render, read once at the end.
#include "raytrace/integrators/film.h"

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

namespace pr::rt {

Film::Film(int width, int height, int spp) : Film(PixelRect{0, 0, width, height}, width, height, spp) {}

Film::Film(const PixelRect& rect, int width, int height, int spp)
    : width_(width), height_(height), spp_(spp), window_(rect) {
  PR_CHECK(width > 0 && height > 0 && spp > 0, "film needs a positive size and spp");
  PR_CHECK(rect.x0 >= 0 && rect.y0 >= 0 && rect.x1 <= width && rect.y1 <= height && rect.pixels() > 0,
           "film window outside the image");
  whole_ = rect.x0 == 0 && rect.y0 == 0 && rect.x1 == width && rect.y1 == height;
  const size_t n = size_t(rect.pixels()) * 3;
  sums_ = std::make_unique<std::atomic<int64_t>[]>(n);
  for (size_t i = 0; i < n; ++i) sums_[i].store(0, std::memory_order_relaxed);
}

void Film::add(uint32_t pixel, const glm::vec3& radiance) {
  PR_DCHECK(pixel < uint32_t(width_) * uint32_t(height_), "pixel outside the film");
  const size_t at = slot(pixel) * 3;
  PR_DCHECK(at < size_t(window_.pixels()) * 3, "pixel outside the film's window");
  for (int c = 0; c < 3; ++c) {
    const float v = radiance[c];
    if (!(v > 0.0f) || !std::isfinite(v)) continue;  // also drops NaN
    const double clamped = std::min(double(v), kMaxContribution);
    const int64_t fixed = std::llround(clamped * kScale);
    if (fixed != 0) sums_[at + c].fetch_add(fixed, std::memory_order_relaxed);
  }
}

FilmBlock Film::block(const PixelRect& rect) const {
  FilmBlock b{rect, {}};
  b.sums.reserve(size_t(rect.pixels()) * 3);
  for (int y = rect.y0; y < rect.y1; ++y)
    for (int x = rect.x0; x < rect.x1; ++x)
      for (int c = 0; c < 3; ++c) b.sums.push_back(sums_[slot(x, y) * 3 + c].load(std::memory_order_relaxed));
  return b;
}

bool Film::anyIn(const PixelRect& rect) const {
  for (int y = rect.y0; y < rect.y1; ++y)
    for (int x = rect.x0; x < rect.x1; ++x)
      for (int c = 0; c < 3; ++c)
        if (sums_[slot(x, y) * 3 + c].load(std::memory_order_relaxed) != 0) return true;
  return false;
}

void Film::addBlock(const FilmBlock& b) {
  PR_CHECK(b.sums.size() == size_t(b.rect.pixels()) * 3, "film block: sums do not match its rectangle");
  size_t i = 0;
  for (int y = b.rect.y0; y < b.rect.y1; ++y)
    for (int x = b.rect.x0; x < b.rect.x1; ++x)
      for (int c = 0; c < 3; ++c, ++i)
        if (b.sums[i] != 0) sums_[slot(x, y) * 3 + c].fetch_add(b.sums[i], std::memory_order_relaxed);
}

image::Image Film::toImage() const {
  image::Image image(width_, height_);
  const double norm = 1.0 / (kScale * double(spp_));
  for (int y = window_.y0; y < window_.y1; ++y)
    for (int x = window_.x0; x < window_.x1; ++x)
      for (int c = 0; c < 3; ++c)
        image.pixels[size_t(y) * size_t(width_) + size_t(x)][c] =
            float(double(sums_[slot(x, y) * 3 + c].load(std::memory_order_relaxed)) * norm);
  return image;
}

}  // namespace pr::rt
