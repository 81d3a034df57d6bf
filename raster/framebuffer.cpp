// RegionFramebuffer storage and comparison. Written by the rasterize and shade stages of the
// owner of one region; read by depth resolve (compositing) and by image output.
#include "raster/framebuffer.h"

#include <algorithm>
#include <cstring>

#include <emmintrin.h>

#include "common/util/error.h"

namespace pr::raster {

RegionFramebuffer::RegionFramebuffer(const Rect& rect) : rect_(rect) {
  PR_CHECK(rect.x1 >= rect.x0 && rect.y1 >= rect.y0, "RegionFramebuffer: inverted rectangle");
  size_t n = static_cast<size_t>(rect.area());
  key_.assign(n, kClearKey);
  triangle_.assign(n, kNoTriangle);
  colour_.assign(n, glm::vec3(0.0f));
}

void RegionFramebuffer::clear() { window().clear(); }

void PixelWindow::clear() const {
  const size_t w = static_cast<size_t>(rect.width());
  for (int y = 0; y < rect.height(); ++y) {
    const size_t row = static_cast<size_t>(y) * stride;
    std::fill_n(keys + row, w, kClearKey);
    std::fill_n(triangles + row, w, kNoTriangle);
    std::fill_n(colours + row, w, glm::vec3(0.0f));
  }
}

void PixelWindow::clearKeys() const {
  const size_t w = static_cast<size_t>(rect.width());
  for (int y = 0; y < rect.height(); ++y) std::fill_n(keys + static_cast<size_t>(y) * stride, w, kClearKey);
}

void PixelWindow::clearColours() const {
  const size_t w = static_cast<size_t>(rect.width());
  for (int y = 0; y < rect.height(); ++y) std::fill_n(colours + static_cast<size_t>(y) * stride, w, glm::vec3(0.0f));
}

PixelWindow RegionFramebuffer::window(const Rect& r) {
  PR_CHECK(r.empty() || intersect(r, rect_) == r, "RegionFramebuffer::window: rectangle outside the buffer");
  if (r.empty()) return PixelWindow{r, static_cast<size_t>(rect_.width()), nullptr, nullptr, nullptr};
  const size_t at = index(r.x0, r.y0);
  return PixelWindow{r, static_cast<size_t>(rect_.width()), key_.data() + at, triangle_.data() + at,
                     colour_.data() + at};
}

namespace {

// Non-temporal copy of n bytes (the 16-byte-aligned middle of dst; the ends by memcpy).
void streamCopy(void* dst, const void* src, size_t n) {
  auto* d = static_cast<char*>(dst);
  const auto* s = static_cast<const char*>(src);
  const size_t head = std::min(n, (16 - reinterpret_cast<uintptr_t>(d) % 16) % 16);
  std::memcpy(d, s, head);
  size_t i = head;
  for (; i + 16 <= n; i += 16)
    _mm_stream_si128(reinterpret_cast<__m128i*>(d + i), _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i)));
  std::memcpy(d + i, s + i, n - i);
}

}  // namespace

void RegionFramebuffer::reshape(const Rect& rect) {
  PR_CHECK(rect.x1 >= rect.x0 && rect.y1 >= rect.y0, "RegionFramebuffer: inverted rectangle");
  rect_ = rect;
  const size_t n = static_cast<size_t>(rect.area());
  key_.resize(n);
  triangle_.resize(n);
  colour_.resize(n);
}

void copyInto(const RegionFramebuffer& src, RegionFramebuffer& dst) { copyInto(src, dst, src.rect()); }

void copyInto(const RegionFramebuffer& src, RegionFramebuffer& dst, const Rect& within) {
  const Rect r = intersect(intersect(src.rect(), dst.rect()), within);
  const size_t w = static_cast<size_t>(r.width());
  for (int y = r.y0; y < r.y1; ++y) {
    streamCopy(dst.keys() + dst.index(r.x0, y), src.keys() + src.index(r.x0, y), w * sizeof(uint64_t));
    streamCopy(dst.colours() + dst.index(r.x0, y), src.colours() + src.index(r.x0, y), w * sizeof(glm::vec3));
  }
  // Streaming stores are weakly ordered: fence them before anyone else may read the frame.
  _mm_sfence();
}

size_t RegionFramebuffer::coveredPixels() const {
  return static_cast<size_t>(std::count_if(key_.begin(), key_.end(), keyCovered));
}

size_t RegionFramebuffer::memoryBytes() const {
  return key_.size() * sizeof(uint64_t) + triangle_.size() * sizeof(uint32_t) +
         colour_.size() * sizeof(glm::vec3);
}

bool identical(const RegionFramebuffer& a, const RegionFramebuffer& b) {
  if (!(a.rect() == b.rect())) return false;
  size_t n = static_cast<size_t>(a.rect().area());
  return std::memcmp(a.keys(), b.keys(), n * sizeof(uint64_t)) == 0 &&
         std::memcmp(a.colours(), b.colours(), n * sizeof(glm::vec3)) == 0;
}

RegionFramebuffer crop(const RegionFramebuffer& fb, const Rect& rect) {
  RegionFramebuffer out(intersect(fb.rect(), rect));
  const Rect& r = out.rect();
  for (int y = r.y0; y < r.y1; ++y) {
    std::copy_n(fb.keys() + fb.index(r.x0, y), r.width(), out.keys() + out.index(r.x0, y));
    std::copy_n(fb.colours() + fb.index(r.x0, y), r.width(), out.colours() + out.index(r.x0, y));
  }
  return out;
}

image::Image toImage(const RegionFramebuffer& fb) {
  image::Image img(fb.width(), fb.height());
  std::copy(fb.colours(), fb.colours() + fb.rect().area(), img.pixels.begin());
  return img;
}

}  // namespace pr::raster
