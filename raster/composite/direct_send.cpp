// Direct-send compositing (sort-last): the screen is cut into P strips of equal expected
// shading cost (the last frame's covered pixels per row), PE i owns strip i; each
// PE sends every other owner the part of its framebuffer inside that owner's strip (P - 1
// messages in the full-frame variant, b * A * (1 - 1/P) bytes per PE on average), then
// each owner depth-composites what it received into its own strip. Also the pixel packing
// shared with binary swap.
#include <algorithm>

#include "common/parallel/channel.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {

PixelMessage packPixels(const RegionFramebuffer& fb, const Rect& region, const Rect& drawn, bool sparse) {
  PixelMessage m;
  const Rect inside = intersect(fb.rect(), region);
  m.drawn = intersect(inside, drawn);
  m.rect = sparse ? m.drawn : inside;
  const Rect& r = m.rect;
  const size_t w = static_cast<size_t>(r.width());
  m.keys.resize(static_cast<size_t>(r.area()));
  for (int y = r.y0; y < r.y1; ++y)
    std::copy_n(fb.keys() + fb.index(r.x0, y), w, m.keys.data() + static_cast<size_t>(y - r.y0) * w);
  return m;
}

void mergePixels(const PixelMessage& m, RegionFramebuffer& dst, Rect& dstDrawn) {
  // Only the sender's drawn part can win the depth test: the rest of the message is clear.
  const Rect both = intersect(m.drawn, dst.rect());
  if (both.empty()) return;
  const Rect& r = m.rect;
  uint64_t* keys = dst.keys();
  uint32_t* triangles = dst.triangles();
  for (int y = both.y0; y < both.y1; ++y) {
    size_t k = static_cast<size_t>(y - r.y0) * static_cast<size_t>(r.width()) + static_cast<size_t>(both.x0 - r.x0);
    size_t i = dst.index(both.x0, y);
    for (int x = both.x0; x < both.x1; ++x, ++k, ++i) {
      if (!depthTest(keys[i], m.keys[k])) continue;
      keys[i] = m.keys[k];
      triangles[i] = kNoTriangle;  // another PE's fragment: the owner resolves it before shading
    }
  }
  dstDrawn = enclose(dstDrawn, both);
}

void recordCompositeTallies(par::Runtime& rt, const std::vector<CompositeTally>& tallies) {
  for (int p = 0; p < rt.pes(); ++p) {
    rt.addCounter("Sort/pixels_sent", p, double(tallies[p].pixelsSent));
    rt.addCounter("Sort/composite_messages", p, double(tallies[p].messages));
    rt.addCounter("Sort/composite_bytes", p, double(tallies[p].bytes));
  }
}

namespace {

class DirectSend : public Compositor {
 public:
  std::string_view name() const override { return "direct-send"; }
  bool cutsEqualStrips(std::span<const double> rowCost, int height) const override {
    return !cutsByRowCost(rowCost, height);
  }

  std::vector<Rect> composite(par::Runtime& rt, std::vector<RegionFramebuffer>& buffers, std::vector<Rect>& drawn,
                              bool sparse, std::span<const double> rowCost) override {
    const int pes = rt.pes();
    const Rect screen = buffers[rt.firstLocalPe()].rect();  // every PE's is full screen
    // Strip i belongs to PE i (fewer strips than PEs only when the screen has fewer rows),
    // cut so that each owner expects the same shading work.
    std::vector<Rect> strips = weightedStripRegions(screen.width(), screen.height(), pes, rowCost);
    const int owners = static_cast<int>(strips.size());

    std::vector<CompositeTally> counters(pes);
    par::Channel<PixelMessage> pixels(rt, "composite pixels", par::MessageKind::Pixels);
    rt.runOnEachPe("direct-send", [&](par::Pe& pe) {
      CompositeTally& c = counters[pe.id()];
      for (int o = 0; o < owners; ++o) {
        if (o == pe.id()) continue;
        PixelMessage m = packPixels(buffers[pe.id()], strips[o], drawn[pe.id()], sparse);
        if (sparse && m.pixels() == 0) continue;  // nothing drawn there: no message
        c.count(m);
        pixels.send(pe, o, std::move(m));
      }
    });

    std::vector<std::vector<PixelMessage>> inbox(pes);
    for (int p = 0; p < pes; ++p) inbox[p] = pixels.drain(p);
    rt.runOnEachPe("direct-send merge", [&](par::Pe& pe) {
      for (const PixelMessage& m : inbox[pe.id()]) mergePixels(m, buffers[pe.id()], drawn[pe.id()]);
    });
    recordCompositeTallies(rt, counters);
    strips.resize(pes);  // PEs beyond the strips own nothing
    return strips;
  }
};

}  // namespace

std::unique_ptr<Compositor> makeDirectSend() { return std::make_unique<DirectSend>(); }

}  // namespace pr::raster
