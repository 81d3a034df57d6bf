// Compositor: the redistribution step of sort-last. Every PE holds a full-screen colour+depth
// framebuffer of its own primitives; compositing moves pixels between PEs as counted messages
// until each screen pixel has met every PE's fragment there and kept the nearest key (depth
// compositing, depth_resolve.h). direct_send.cpp: each PE sends each region straight to its
// owner; binary_swap.cpp: log2 P pairwise exchanges of halves (Ma et al. 1994); one line each
// in registry.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "common/parallel/runtime.h"
#include "common/util/registry.h"
#include "raster/framebuffer.h"

namespace pr::raster {

// Bytes per pixel on the wire: full frame = depth key (8) + colour (3 floats, 12); sparse adds
// the pixel's 4-byte index inside the message rectangle. Message headers are not counted, so
// full-frame volumes equal the analytic b * A * (1 - 1/P) exactly.
inline constexpr size_t kFullPixelBytes = sizeof(uint64_t) + sizeof(glm::vec3);
inline constexpr size_t kSparsePixelBytes = kFullPixelBytes + sizeof(uint32_t);

// Pixels of one rectangle of a PE's framebuffer. Full: every pixel in row-major order (index
// empty). Sparse: only covered pixels, index = row-major position inside rect.
struct PixelMessage {
  Rect rect;
  std::vector<uint32_t> index;
  std::vector<uint64_t> keys;
  std::vector<glm::vec3> colours;

  size_t pixels() const { return keys.size(); }
  size_t bytes(bool sparse) const { return pixels() * (sparse ? kSparsePixelBytes : kFullPixelBytes); }
};

// The part of fb inside rect, as the sending PE packs it.
PixelMessage packPixels(const RegionFramebuffer& fb, const Rect& rect, bool sparse);
// Depth-composites a received message into dst (the receiver's own buffer), where they overlap.
void mergePixels(const PixelMessage& message, RegionFramebuffer& dst);

// Compositing traffic of one PE, kept while the compositor's stages run and then put in the
// run record per PE (Sort/pixels_sent, Sort/composite_messages, Sort/composite_bytes: what
// the Channel counted, in pixels).
struct CompositeTally {
  uint64_t pixelsSent = 0, messages = 0, bytes = 0;
  void count(const PixelMessage& m, size_t bytesSent) {
    pixelsSent += m.pixels();
    messages += 1;
    bytes += bytesSent;
  }
};
void recordCompositeTallies(par::Runtime& runtime, const std::vector<CompositeTally>& tallies);

class Compositor {
 public:
  virtual ~Compositor() = default;
  virtual std::string_view name() const = 0;  // "direct-send" | "binary-swap"
  // Called by the controlling thread after every PE has rendered and shaded into buffers[pe]
  // (full screen each); runs its own stages, merging received pixels into the receiver's own
  // buffer. Returns rects: afterwards buffers[p] holds the composited pixels inside rects[p]
  // (disjoint rectangles that cover the screen; empty for a PE left without one).
  // Each PE's traffic goes to the run record (recordCompositeTallies). Throws pr::InputError
  // when the method cannot run with this PE count.
  virtual std::vector<Rect> composite(par::Runtime& runtime, std::vector<RegionFramebuffer>& buffers,
                                      bool sparse) = 0;
};

// Factories, one per compositor file.
std::unique_ptr<Compositor> makeDirectSend();
std::unique_ptr<Compositor> makeBinarySwap();

// Registry: name -> factory -> description (registry.cpp); feeds --compositor, its --help
// and validation, and the sort-last summary.
using CompositorInfo = RegistryEntry<std::unique_ptr<Compositor> (*)()>;
using CompositorRegistry = Registry<std::unique_ptr<Compositor> (*)()>;
const CompositorRegistry& compositors();
// Throws pr::InputError naming the unknown compositor and listing the valid ones.
std::unique_ptr<Compositor> makeCompositor(std::string_view name);

}  // namespace pr::raster
