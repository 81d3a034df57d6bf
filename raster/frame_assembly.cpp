// Frame assembly: region messages to the assembler PE and the handler that stores them.
#include "raster/frame_assembly.h"

#include <utility>

#include "common/util/error.h"

namespace pr::par {

void Wire<raster::RegionFramebuffer>::encode(const raster::RegionFramebuffer& b, WireWriter& w) {
  const size_t pixels = static_cast<size_t>(b.rect().area());
  w.reserve(raster::regionMessageBytes(b.rect()));
  w.value(b.rect());
  w.raw(b.keys(), pixels * sizeof(uint64_t));
  w.raw(b.colours(), pixels * sizeof(glm::vec3));
}

raster::RegionFramebuffer Wire<raster::RegionFramebuffer>::decode(WireReader& r) { return raster::decodeRegion(r, nullptr); }

}  // namespace pr::par

namespace pr::raster {

RegionFramebuffer decodeRegion(par::WireReader& r, RegionBufferPool* pool) {
  const Rect rect = r.value<Rect>();
  if (rect.width() < 0 || rect.height() < 0) throw par::WireError("a region message names an inverted rectangle");
  const size_t pixels = static_cast<size_t>(rect.area());
  if (pixels > r.remaining() / kRegionPixelBytes) throw par::WireError("a region message is shorter than its rectangle");
  RegionFramebuffer b = pool ? pool->take(rect) : RegionFramebuffer(rect);
  r.raw(b.keys(), pixels * sizeof(uint64_t));
  r.raw(b.colours(), pixels * sizeof(glm::vec3));
  return b;
}

RegionFramebuffer RegionBufferPool::take(const Rect& rect) {
  RegionFramebuffer buffer;
  {
    std::lock_guard lock(mutex_);
    if (!free_.empty()) {
      buffer = std::move(free_.back());
      free_.pop_back();
    }
  }
  buffer.reshape(rect);
  return buffer;
}

void RegionBufferPool::give(RegionFramebuffer&& buffer) {
  std::lock_guard lock(mutex_);
  free_.push_back(std::move(buffer));
}

FrameAssembly::FrameAssembly(par::Runtime& runtime, RegionFramebuffer& frame, RegionBufferPool& pool)
    : runtime_(runtime),
      frame_(frame),
      pool_(pool),
      regions_(runtime, "frame regions", par::MessageKind::Results,
               [this](par::Pe&, RegionFramebuffer&& region) { store(std::move(region)); }) {
  // A region from another rank lands in storage from the pool, where store() puts it back: a
  // fresh buffer per message would grow the pool by a frame's regions every frame, each one
  // faulted in page by page (sort-middle at 2 ranks: most of rank 0's time between regions).
  regions_.decodeWith([this](par::WireReader& r) { return decodeRegion(r, &pool_); });
}

RegionFramebuffer& FrameAssembly::frame(const par::Pe& pe) {
  PR_CHECK(assembles(pe), "FrameAssembly: PE " + std::to_string(pe.id()) + " asked for the assembler's frame");
  return frame_;
}

void FrameAssembly::store(RegionFramebuffer&& region) {
  copyInto(region, frame_);
  pool_.give(std::move(region));
}

void FrameAssembly::serve(par::Pe& pe) {
  if (!assembles(pe)) return;
  // As a PE waiting inside a task does (Runtime::serveOne): the regions that have arrived, and
  // any request another PE waits on.
  const double t0 = runtime_.now();
  while (runtime_.serveOne(pe)) {
  }
  servedSeconds_ += runtime_.now() - t0;
}

void FrameAssembly::deliver(par::Pe& pe, RegionFramebuffer&& region) {
  if (assembles(pe)) {
    store(std::move(region));
    return;
  }
  regions_.send(pe, kAssemblerPe, std::move(region));
}

void FrameAssembly::deliver(par::Pe& pe, const RegionFramebuffer& src, const Rect& within) {
  const Rect r = intersect(src.rect(), within);
  if (r.empty()) return;
  if (assembles(pe)) {
    copyInto(src, frame_, r);
    return;
  }
  RegionFramebuffer part = pool_.take(r);
  copyInto(src, part);
  deliver(pe, std::move(part));
}

}  // namespace pr::raster
