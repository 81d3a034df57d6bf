// Image assembly in the raster pipelines: results are transfers too (shared/DESIGN.md rule 1).
// The assembler PE (PE 0, as in the ray tracers' film_assembly.h) holds the frame; a region
// owner that finishes a region (sort-first and sort-middle, static or dynamic regions) or a
// sort-last PE that finished compositing its rectangle delivers the pixels to the assembler as
// one message on the "frame regions" Channel (kind results), whose handler stores them in the
// frame. What the assembler draws itself it stores in place: no message, so P = 1 moves nothing.
// All three sort points call this one piece (bins.h's RegionDrawer and sort_last.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include <glm/glm.hpp>

#include "common/parallel/channel.h"
#include "raster/framebuffer.h"

namespace pr::raster {

inline constexpr int kAssemblerPe = 0;

// A region message on the wire: a header naming the rectangle (x0, y0, x1, y1 as four int32)
// and, per pixel, what the frame holds: the depth keys (8 bytes each), then the linear colours
// (three floats, 12 bytes each), row-major over the rectangle (Wire<RegionFramebuffer> below).
// Inside a rank the message is the drawn buffer itself (moved, not copied); its triangle
// indices are not part of the message: the assembler never reads them (they mean something
// only in the buffer that rasterized them), and a decoded region has none.
inline constexpr size_t kRegionHeaderBytes = 4 * sizeof(int32_t);
static_assert(sizeof(Rect) == kRegionHeaderBytes, "a region message's header is its Rect");
inline constexpr size_t kRegionPixelBytes = sizeof(uint64_t) + sizeof(glm::vec3);
inline size_t regionMessageBytes(const Rect& r) {
  return kRegionHeaderBytes + static_cast<size_t>(r.area()) * kRegionPixelBytes;
}

}  // namespace pr::raster

namespace pr::par {
template <>
struct Wire<raster::RegionFramebuffer> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const raster::RegionFramebuffer& b) { return raster::regionMessageBytes(b.rect()); }
  static void encode(const raster::RegionFramebuffer& b, WireWriter& w);
  static raster::RegionFramebuffer decode(WireReader& r);
};
}  // namespace pr::par

namespace pr::raster {

// Storage for region messages, kept by a sort point from frame to frame: a sender takes a
// buffer, draws into it and sends it; the assembler's handler, once it has stored the pixels,
// gives the emptied storage back. Only storage comes back (no pixel content), so there is no
// transfer to count; it spares an allocation and a zero fill per region. Thread-safe.
class RegionBufferPool {
 public:
  // A buffer covering rect; its pixels are unspecified (the drawer writes every one).
  RegionFramebuffer take(const Rect& rect);
  void give(RegionFramebuffer&& buffer);

 private:
  std::mutex mutex_;
  std::vector<RegionFramebuffer> free_;
};

// Reads a region message: into storage from pool when there is one (its triangle indices
// unspecified), else into a new buffer. Throws par::WireError on a malformed message.
RegionFramebuffer decodeRegion(par::WireReader& r, RegionBufferPool* pool);

class FrameAssembly {
 public:
  // frame: the full-screen image the render returns, written by the assembler PE only.
  // Created by the controlling thread between stages, before the stages that deliver.
  FrameAssembly(par::Runtime& runtime, RegionFramebuffer& frame, RegionBufferPool& pool);

  bool assembles(const par::Pe& pe) const { return pe.id() == kAssemblerPe; }
  // The frame itself, for the assembler drawing a region of it in place (no one else may).
  RegionFramebuffer& frame(const par::Pe& pe);
  // On a PE that is not the assembler: a buffer to draw a region in, then deliver.
  RegionFramebuffer buffer(const Rect& rect) { return pool_.take(rect); }

  // On PE pe inside a task or handler: the finished region (all of region's rectangle)
  // reaches the frame, stored in place on the assembler, as one message from any other PE.
  void deliver(par::Pe& pe, RegionFramebuffer&& region);
  // The same for the part of src inside within (sort-last: a PE's composited rectangle of its
  // full-screen buffer); nothing when that part is empty.
  void deliver(par::Pe& pe, const RegionFramebuffer& src, const Rect& within);

  // On the assembler inside one of its tasks: stores the region messages that have arrived (and
  // answers any other message waiting for it, Runtime::serveOne).
  // The runtime hands messages to their handler between tasks only, so an assembler drawing
  // all its regions in one task calls this between them; otherwise every other PE's regions
  // would stay in flight (and their buffers out of the pool, out of cache) until it is done.
  void serve(par::Pe& pe);
  // Seconds the assembler has spent in serve() so far (read on the assembler only).
  double servedSeconds() const { return servedSeconds_; }

 private:
  void store(RegionFramebuffer&& region);

  par::Runtime& runtime_;
  RegionFramebuffer& frame_;
  RegionBufferPool& pool_;
  par::Channel<RegionFramebuffer> regions_;
  double servedSeconds_ = 0.0;
};

}  // namespace pr::raster
