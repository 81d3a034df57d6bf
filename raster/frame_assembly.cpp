// Frame assembly: region messages to the assembler PE and the handler that stores them.
#include "raster/frame_assembly.h"

#include <utility>

#include "common/util/error.h"

namespace pr::raster {

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
               [this](par::Pe&, RegionFramebuffer&& region) { store(std::move(region)); }) {}

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
  // As the runtime does between tasks (and TilePull inside one): a handled message is done;
  // the task calling this is still outstanding, so this is never the stage's last unit.
  while (regions_.handleOne(pe)) {
    pe.counters().messagesHandled.fetch_add(1, std::memory_order_relaxed);
    runtime_.outstanding().done();
  }
}

void FrameAssembly::deliver(par::Pe& pe, RegionFramebuffer&& region) {
  if (assembles(pe)) {
    store(std::move(region));
    return;
  }
  const size_t bytes = regionMessageBytes(region.rect());
  regions_.sendDeclared(pe, kAssemblerPe, std::move(region), bytes);
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
