// Binary-swap compositing (sort-last; Ma, Painter, Hansen, Krogh 1994): in round k PE p pairs
// with p XOR 2^k; both hold the same rectangle, cut it in half (across its longer side), keep
// one half and send the other to the partner, then depth-composite the partner's half into
// theirs. After log2 P rounds each PE owns a disjoint 1/P of the screen; in the full-frame
// variant each PE sent A/2 + A/4 + ... + A/P = A (1 - 1/P) pixels in log2 P messages.
#include <bit>
#include <string>
#include <utility>

#include "common/parallel/channel.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "raster/sort/region_assignment.h"

namespace pr::raster {
namespace {

// The two halves of r; both partners compute the same cut.
std::pair<Rect, Rect> halves(const Rect& r) {
  if (r.height() >= r.width()) {
    const int mid = r.y0 + r.height() / 2;
    return {Rect{r.x0, r.y0, r.x1, mid}, Rect{r.x0, mid, r.x1, r.y1}};
  }
  const int mid = r.x0 + r.width() / 2;
  return {Rect{r.x0, r.y0, mid, r.y1}, Rect{mid, r.y0, r.x1, r.y1}};
}

class BinarySwap : public Compositor {
 public:
  std::string_view name() const override { return "binary-swap"; }

  std::vector<Rect> composite(par::Runtime& rt, std::vector<RegionFramebuffer>& buffers, std::vector<Rect>& drawn,
                              bool sparse, std::span<const double> /*rowCost*/) override {
    const int pes = rt.pes();
    if (!std::has_single_bit(static_cast<unsigned>(pes)))
      throw InputError("binary-swap compositing needs a power-of-two PE count, got " + std::to_string(pes) +
                       " (use direct-send)");
    const int rounds = std::countr_zero(static_cast<unsigned>(pes));

    // kept[p]: the rectangle PE p still composites; its pixels stay in buffers[p].
    std::vector<Rect> kept(pes, buffers[rt.firstLocalPe()].rect());  // every PE's is full screen
    std::vector<std::vector<PixelMessage>> inbox(pes);
    std::vector<CompositeTally> counters(pes);
    for (int k = 0; k < rounds; ++k) {
      par::Channel<PixelMessage> pixels(rt, "binary-swap pixels", par::MessageKind::Pixels);
      rt.runOnEachPe("binary-swap round " + std::to_string(k), [&](par::Pe& pe) {
                    const int p = pe.id();
                    for (const PixelMessage& m : inbox[p]) mergePixels(m, buffers[p], drawn[p]);
                    inbox[p].clear();
                    const auto [lower, upper] = halves(kept[p]);
                    const bool keepLower = ((p >> k) & 1) == 0;
                    PixelMessage m = packPixels(buffers[p], keepLower ? upper : lower, drawn[p], sparse);
                    kept[p] = keepLower ? lower : upper;
                    if (sparse && m.pixels() == 0) return;  // nothing drawn there: no message
                    counters[p].count(m);
                    pixels.send(pe, p ^ (1 << k), std::move(m));
                  });
      for (int p = 0; p < pes; ++p) inbox[p] = pixels.drain(p);
    }
    rt.runOnEachPe("binary-swap merge", [&](par::Pe& pe) {
      for (const PixelMessage& m : inbox[pe.id()]) mergePixels(m, buffers[pe.id()], drawn[pe.id()]);
    });
    recordCompositeTallies(rt, counters);
    return kept;
  }
};

}  // namespace

std::unique_ptr<Compositor> makeBinarySwap() { return std::make_unique<BinarySwap>(); }

}  // namespace pr::raster
