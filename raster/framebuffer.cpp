// RegionFramebuffer storage and comparison. Written by the rasterize and shade stages of the
// owner of one region; read by depth resolve (compositing) and by image output.
#include "raster/framebuffer.h"

#include <algorithm>
#include <cstring>

#include "common/util/error.h"

namespace pr::raster {

RegionFramebuffer::RegionFramebuffer(const Rect& rect) : rect_(rect) {
  PR_CHECK(rect.x1 >= rect.x0 && rect.y1 >= rect.y0, "RegionFramebuffer: inverted rectangle");
  size_t n = static_cast<size_t>(rect.area());
  key_.assign(n, kClearKey);
  triangle_.assign(n, kNoTriangle);
  colour_.assign(n, glm::vec3(0.0f));
}

void RegionFramebuffer::clear() {
  std::fill(key_.begin(), key_.end(), kClearKey);
  std::fill(triangle_.begin(), triangle_.end(), kNoTriangle);
  std::fill(colour_.begin(), colour_.end(), glm::vec3(0.0f));
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
