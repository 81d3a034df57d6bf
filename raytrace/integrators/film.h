// Film: where every tracer's shading results end up. Contributions are summed in fixed point
// (int64 per channel, value x 2^24) with relaxed atomic adds, so the sum is independent of the
// order in which PEs deliver them: integer addition is associative, float addition is not.
// That is what makes images bit-identical for every tracer, P and schedule. Film -> Image last.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "common/image/image.h"
#include "common/parallel/wire.h"

namespace pr::rt {

// A rectangle of pixels [x0, x1) x [y0, y1): one image-space tile, or the whole image.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int64_t pixels() const { return int64_t(x1 - x0) * int64_t(y1 - y0); }
};

// The fixed-point sums of a rectangle of a film, row-major, three channels per pixel: what a PE
// sends to the PE that assembles the image (film_assembly.h).
struct FilmBlock {
  PixelRect rect;
  std::vector<int64_t> sums;
  static constexpr size_t kHeaderBytes = sizeof(PixelRect);
  size_t bytes() const { return kHeaderBytes + sums.size() * sizeof(int64_t); }
};

}  // namespace pr::rt

// A film block on the wire: its rectangle, then its sums (their count follows from the
// message's length).
namespace pr::par {
template <>
struct Wire<rt::FilmBlock> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const rt::FilmBlock& b) { return b.bytes(); }
  static void encode(const rt::FilmBlock& b, WireWriter& w) {
    w.value(b.rect);
    w.elements(std::span<const int64_t>(b.sums));
  }
  static rt::FilmBlock decode(WireReader& r) {
    rt::FilmBlock b;
    b.rect = r.value<rt::PixelRect>();
    b.sums = r.elements<int64_t>();
    return b;
  }
};
}  // namespace pr::par

namespace pr::rt {

class Film {
 public:
  // 2^24: resolves contributions down to 6e-8, well below an 8-bit or half-float step.
  static constexpr double kScale = 16777216.0;
  // A single contribution is clamped to this before conversion, so int64 sums of up to
  // 2^63 / (kMaxContribution * kScale) ~ 5e5 contributions per pixel and channel cannot overflow.
  static constexpr double kMaxContribution = 1.0e6;

  Film(int width, int height, int spp);
  // A film over the window `rect` of a width x height image: pixels keep their image indices
  // (y * width + x) and must lie inside the window (a tile's own film in image-space tracing).
  Film(const PixelRect& rect, int width, int height, int spp);

  int width() const { return width_; }
  int height() const { return height_; }
  int spp() const { return spp_; }
  const PixelRect& window() const { return window_; }

  // Adds radiance to a pixel (index y * width + x). Thread-safe; order-independent. A
  // non-finite or negative component is dropped (a guard; integrators do not produce them).
  void add(uint32_t pixel, const glm::vec3& radiance);

  // The fixed-point sum of one channel (for tests of order independence).
  int64_t raw(uint32_t pixel, int channel) const { return sums_[slot(pixel) * 3 + channel].load(std::memory_order_relaxed); }

  // The sums inside rect (which must lie inside the window), and whether any of them is non-zero.
  FilmBlock block(const PixelRect& rect) const;
  bool anyIn(const PixelRect& rect) const;
  // Adds a block's sums (its rect inside the window). Thread-safe; order-independent.
  void addBlock(const FilmBlock& block);

  // Mean radiance per pixel: sum / spp, for the whole image (a windowed film: zero outside the
  // window). Called after the render, from one thread.
  image::Image toImage() const;

 private:
  // Position of image pixel `pixel` in sums_ (divided by three channels).
  size_t slot(uint32_t pixel) const {
    if (whole_) return size_t(pixel);
    const int x = int(pixel % uint32_t(width_)), y = int(pixel / uint32_t(width_));
    return size_t(y - window_.y0) * size_t(window_.x1 - window_.x0) + size_t(x - window_.x0);
  }
  size_t slot(int x, int y) const { return slot(uint32_t(y) * uint32_t(width_) + uint32_t(x)); }

  int width_, height_, spp_;
  PixelRect window_;
  bool whole_ = true;
  std::unique_ptr<std::atomic<int64_t>[]> sums_;
};

}  // namespace pr::rt
