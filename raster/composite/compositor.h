// Compositor: the redistribution step of sort-last. Every PE holds a full-screen depth buffer
// of its own primitives' fragments; compositing moves fragment keys between PEs as counted
// messages until each screen pixel has met every PE's fragment there and kept the nearest key
// (depth compositing, depth_resolve.h), which the region's owner then shades. direct_send.cpp: each PE sends each region straight to its
// owner; binary_swap.cpp: log2 P pairwise exchanges of halves (Ma et al. 1994); one line each
// in registry.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"
#include "common/util/registry.h"
#include "raster/framebuffer.h"

namespace pr::raster {

// Bytes per pixel on the wire: the fragment's depth key (8; it names the primitive, so the
// region's owner shades it after compositing). A message also carries its two rectangles
// (kPixelHeaderBytes), so a full-frame compositing step moves the analytic b * A * (1 - 1/P)
// pixel bytes per PE plus one header per message.
inline constexpr size_t kPixelBytes = sizeof(uint64_t);
inline constexpr size_t kPixelHeaderBytes = 2 * sizeof(Rect);

// Pixels of one rectangle of a PE's framebuffer, every pixel in row-major order. `drawn` is the
// part of rect where the sender's buffer may hold fragments (outside it every pixel is clear,
// so the receiver skips it). Full frame: rect is the whole region. Sparse: rect is the
// region's bounding rectangle of what the sender drew (Ma et al. 1994), rect == drawn.
// On the wire (Wire<PixelMessage> below): rect, drawn, then the keys.
struct PixelMessage {
  Rect rect;
  Rect drawn;
  std::vector<uint64_t> keys;

  size_t pixels() const { return keys.size(); }
  size_t bytes() const { return kPixelHeaderBytes + pixels() * kPixelBytes; }
};

}  // namespace pr::raster

namespace pr::par {
template <>
struct Wire<raster::PixelMessage> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const raster::PixelMessage& m) { return m.bytes(); }
  static void encode(const raster::PixelMessage& m, WireWriter& w) {
    w.value(m.rect);
    w.value(m.drawn);
    w.elements(std::span<const uint64_t>(m.keys));
  }
  static raster::PixelMessage decode(WireReader& r) {
    raster::PixelMessage m;
    m.rect = r.value<raster::Rect>();
    m.drawn = r.value<raster::Rect>();
    m.keys = r.elements<uint64_t>();
    if (m.keys.size() != static_cast<size_t>(m.rect.area()))
      throw WireError("a pixel message's keys do not fill its rectangle");
    // The receiver reads keys where `drawn` meets its buffer, indexed within rect.
    if (!m.drawn.empty() && !(raster::intersect(m.drawn, m.rect) == m.drawn))
      throw WireError("a pixel message's drawn part lies outside its rectangle");
    return m;
  }
};
}  // namespace pr::par

namespace pr::raster {

// The part of fb inside region, as the sending PE packs it; drawn bounds the pixels of fb
// that may hold fragments (every other pixel is clear).
PixelMessage packPixels(const RegionFramebuffer& fb, const Rect& region, const Rect& drawn, bool sparse);
// Depth-composites a received message into dst (the receiver's own buffer), where they overlap,
// and widens dstDrawn (the receiver's bounding rectangle of drawn pixels) by what it stored.
void mergePixels(const PixelMessage& message, RegionFramebuffer& dst, Rect& dstDrawn);

// Compositing traffic of one PE, kept while the compositor's stages run and then put in the
// run record per PE (Sort/pixels_sent, Sort/composite_messages, Sort/composite_bytes: what
// the Channel counted, in pixels).
struct CompositeTally {
  uint64_t pixelsSent = 0, messages = 0, bytes = 0;
  void count(const PixelMessage& m) {
    pixelsSent += m.pixels();
    messages += 1;
    bytes += m.bytes();  // the encoding's size, as the Channel counts it
  }
};
void recordCompositeTallies(par::Runtime& runtime, const std::vector<CompositeTally>& tallies);

class Compositor {
 public:
  virtual ~Compositor() = default;
  virtual std::string_view name() const = 0;  // "direct-send" | "binary-swap"
  // Called by the controlling thread after every PE has rendered and shaded into buffers[pe]
  // (full screen each; every pixel outside drawn[pe] is clear; across ranks a rank holds the
  // buffers of its own PEs only); runs its own stages, merging
  // received pixels into the receiver's own buffer and widening its drawn[pe] by them. Returns rects: afterwards buffers[p] holds the composited pixels inside rects[p]
  // (disjoint rectangles that cover the screen; empty for a PE left without one).
  // Each PE's traffic goes to the run record (recordCompositeTallies). rowCost: the expected
  // cost of shading each screen row (the last frame's), or empty when unknown; direct-send cuts
  // its strips at equal cost, binary-swap's halves are fixed by its exchange pattern. Throws
  // pr::InputError when the method cannot run with this PE count.
  virtual std::vector<Rect> composite(par::Runtime& runtime, std::vector<RegionFramebuffer>& buffers,
                                      std::vector<Rect>& drawn, bool sparse, std::span<const double> rowCost) = 0;
  // Whether composite() with this rowCost cuts the screen's `height` rows into strips of equal
  // height at any P (par::kStripCells), so the simulator can cut a record's rows again at
  // another P; false where the regions follow the costs or the exchange pattern.
  virtual bool cutsEqualStrips(std::span<const double> /*rowCost*/, int /*height*/) const { return false; }
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
