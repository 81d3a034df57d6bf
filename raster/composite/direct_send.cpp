// Direct-send compositing (sort-last): the screen is cut into P strips, PE i owns strip i; each
// PE sends every other owner the part of its framebuffer inside that owner's strip (P - 1
// messages of A / P pixels in the full-frame variant: b * A * (1 - 1/P) bytes per PE), then
// each owner depth-composites what it received into its own strip. Also the pixel packing
// shared with binary swap.
#include <algorithm>

#include "common/parallel/channel.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {

PixelMessage packPixels(const RegionFramebuffer& fb, const Rect& rect, bool sparse) {
  PixelMessage m;
  m.rect = intersect(fb.rect(), rect);
  const Rect& r = m.rect;
  if (!sparse) {
    // Full frame: every pixel, row by row.
    const size_t w = static_cast<size_t>(r.width());
    m.keys.resize(static_cast<size_t>(r.area()));
    m.colours.resize(static_cast<size_t>(r.area()));
    for (int y = r.y0; y < r.y1; ++y) {
      const size_t row = static_cast<size_t>(y - r.y0) * w;
      std::copy_n(fb.keys() + fb.index(r.x0, y), w, m.keys.data() + row);
      std::copy_n(fb.colours() + fb.index(r.x0, y), w, m.colours.data() + row);
    }
    return m;
  }
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const size_t i = fb.index(x, y);
      if (!keyCovered(fb.keys()[i])) continue;
      m.index.push_back(static_cast<uint32_t>((y - r.y0) * r.width() + (x - r.x0)));
      m.keys.push_back(fb.keys()[i]);
      m.colours.push_back(fb.colours()[i]);
    }
  }
  return m;
}

namespace {

// Keeps (key, colour) at dst's pixel i when it beats what is there.
inline void mergePixel(RegionFramebuffer& dst, size_t i, uint64_t key, const glm::vec3& colour) {
  if (!depthTest(dst.keys()[i], key)) return;
  dst.keys()[i] = key;
  dst.colours()[i] = colour;
  dst.triangles()[i] = kNoTriangle;
}

}  // namespace

void mergePixels(const PixelMessage& m, RegionFramebuffer& dst) {
  const Rect& r = m.rect;
  if (m.index.empty() && m.pixels() == static_cast<size_t>(r.area())) {
    // Full frame: row by row over the part inside dst.
    const Rect both = intersect(r, dst.rect());
    for (int y = both.y0; y < both.y1; ++y) {
      size_t k = static_cast<size_t>(y - r.y0) * static_cast<size_t>(r.width()) + static_cast<size_t>(both.x0 - r.x0);
      size_t i = dst.index(both.x0, y);
      for (int x = both.x0; x < both.x1; ++x, ++k, ++i) mergePixel(dst, i, m.keys[k], m.colours[k]);
    }
    return;
  }
  for (size_t k = 0; k < m.pixels(); ++k) {
    const uint32_t local = m.index.empty() ? static_cast<uint32_t>(k) : m.index[k];
    const int x = r.x0 + static_cast<int>(local % static_cast<uint32_t>(r.width()));
    const int y = r.y0 + static_cast<int>(local / static_cast<uint32_t>(r.width()));
    if (dst.rect().contains(x, y)) mergePixel(dst, dst.index(x, y), m.keys[k], m.colours[k]);
  }
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

  std::vector<Rect> composite(par::Runtime& rt, std::vector<RegionFramebuffer>& buffers, bool sparse) override {
    const int pes = rt.pes();
    const Rect screen = buffers[0].rect();
    // Strip i belongs to PE i (fewer strips than PEs only when the screen has fewer rows).
    std::vector<Rect> strips = stripRegions(screen.width(), screen.height(), pes);
    const int owners = static_cast<int>(strips.size());

    std::vector<CompositeTally> counters(pes);
    par::Channel<PixelMessage> pixels(rt, "composite pixels", par::MessageKind::Pixels);
    rt.runOnEachPe("direct-send", [&](par::Pe& pe) {
      CompositeTally& c = counters[pe.id()];
      for (int o = 0; o < owners; ++o) {
        if (o == pe.id()) continue;
        PixelMessage m = packPixels(buffers[pe.id()], strips[o], sparse);
        if (sparse && m.pixels() == 0) continue;  // nothing covered there: no message
        const size_t bytes = m.bytes(sparse);
        c.count(m, bytes);
        pixels.send(pe, o, std::move(m), bytes);
      }
    });

    std::vector<std::vector<PixelMessage>> inbox(pes);
    for (int p = 0; p < pes; ++p) inbox[p] = pixels.drain(p);
    rt.runOnEachPe("direct-send merge", [&](par::Pe& pe) {
      for (const PixelMessage& m : inbox[pe.id()]) mergePixels(m, buffers[pe.id()]);
    });
    recordCompositeTallies(rt, counters);
    strips.resize(pes);  // PEs beyond the strips own nothing
    return strips;
  }
};

}  // namespace

std::unique_ptr<Compositor> makeDirectSend() { return std::make_unique<DirectSend>(); }

}  // namespace pr::raster
