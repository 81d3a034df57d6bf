// RegionFramebuffer: colour, depth key (depth + primitive order) and triangle index for one
// screen rectangle (a tile, a strip, or the whole screen). The frame is one of these, written
// by the assembler PE only (frame_assembly.h): it draws its own regions in place through
// PixelWindows and copyInto() stores the finished regions other PEs send it; sort-last PEs hold
// a full-screen one each and resolveInto() composites them.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/image/image.h"
#include "raster/region.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {

// Marks a pixel whose triangle index is unknown (empty, or composited from another buffer).
inline constexpr uint32_t kNoTriangle = 0xffffffffu;

// A rectangle of some framebuffer's pixels, addressed in that framebuffer's rows: what the
// rasterize and shade stages draw into. The sequential pipeline and the assembler PE draw a
// region straight into the frame through a window on it; any other PE draws into a buffer of
// its own and sends it (frame_assembly.h). A RegionFramebuffer is also a window on all of itself.
struct PixelWindow {
  Rect rect;
  size_t stride = 0;               // pixels per row of the arrays below
  uint64_t* keys = nullptr;        // each points at pixel (rect.x0, rect.y0)
  uint32_t* triangles = nullptr;
  glm::vec3* colours = nullptr;

  // Offset of screen pixel (x, y), inside rect, from the pointers above.
  size_t index(int x, int y) const {
    return static_cast<size_t>(y - rect.y0) * stride + static_cast<size_t>(x - rect.x0);
  }
  // The cleared state (no fragment, no triangle, colour 0) for every pixel of rect.
  void clear() const;
  // Parts of it, for a buffer whose owner knows the rest needs none: the keys only (no
  // fragment; a triangle index means nothing where the key is clear), or the colours only.
  void clearKeys() const;
  void clearColours() const;
};

class RegionFramebuffer {
 public:
  RegionFramebuffer() = default;
  explicit RegionFramebuffer(const Rect& rect);

  // Back to the cleared state: key kClearKey (no fragment), no triangle, background colour 0.
  void clear();

  const Rect& rect() const { return rect_; }
  int width() const { return rect_.width(); }
  int height() const { return rect_.height(); }

  // Index of screen pixel (x, y), which must lie inside rect().
  size_t index(int x, int y) const {
    return static_cast<size_t>(y - rect_.y0) * static_cast<size_t>(rect_.width()) +
           static_cast<size_t>(x - rect_.x0);
  }

  // Per-pixel arrays, row-major over rect(). key: fragmentKey() of the visible fragment.
  // triangle: index of that fragment's ScreenTriangle in the list that was rasterized into this
  // buffer (valid only in the buffer that rasterized it). colour: linear radiance after shading.
  uint64_t* keys() { return key_.data(); }
  const uint64_t* keys() const { return key_.data(); }
  uint32_t* triangles() { return triangle_.data(); }
  const uint32_t* triangles() const { return triangle_.data(); }
  glm::vec3* colours() { return colour_.data(); }
  const glm::vec3* colours() const { return colour_.data(); }

  uint64_t key(int x, int y) const { return key_[index(x, y)]; }
  uint32_t triangle(int x, int y) const { return triangle_[index(x, y)]; }
  const glm::vec3& colour(int x, int y) const { return colour_[index(x, y)]; }

  // Makes this buffer cover rect, keeping its storage when it is large enough (a per-PE scratch
  // tile reused for region after region); the pixels are unspecified until clear().
  void reshape(const Rect& rect);

  // The whole buffer, or the part of it inside r (which must lie inside rect()).
  PixelWindow window() { return window(rect_); }
  PixelWindow window(const Rect& r);

  // Number of pixels holding a fragment.
  size_t coveredPixels() const;
  size_t memoryBytes() const;

 private:
  Rect rect_;
  std::vector<uint64_t> key_;
  std::vector<uint32_t> triangle_;
  std::vector<glm::vec3> colour_;
};

// True when both cover the same rectangle and hold bit-identical keys and colours.
bool identical(const RegionFramebuffer& a, const RegionFramebuffer& b);

// Stores src's pixels in dst where the two overlap: keys and colours copied; dst's triangle
// indices are left alone (an index means something only in the buffer that rasterized the
// pixel). For finished regions that are disjoint and cover the frame between them. The
// frame is written once per frame and not read back while drawing, so the stores bypass the
// cache (no read of the old frame contents); they are complete when copyInto returns.
void copyInto(const RegionFramebuffer& src, RegionFramebuffer& dst);
// The same for the pixels inside `within` only.
void copyInto(const RegionFramebuffer& src, RegionFramebuffer& dst, const Rect& within);

// The part of fb inside rect (intersected with fb's rectangle): keys and colours copied,
// triangle indices kNoTriangle. What a sort-last PE sends to the owner of a screen region.
RegionFramebuffer crop(const RegionFramebuffer& fb, const Rect& rect);

// The colours as an image of the rectangle's size (row 0 = the rectangle's top row), for
// image output and comparison (common/image).
image::Image toImage(const RegionFramebuffer& fb);

}  // namespace pr::raster
