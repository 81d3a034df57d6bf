// Tests of RegionFramebuffer and depth compositing: crop + resolve reassemble an image, the
// smaller key wins whatever the compositing order, and toImage keeps the colours.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>

#include "raster/framebuffer.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {
namespace {

// A framebuffer whose pixels hold distinct keys and colours derived from (x, y, seed).
RegionFramebuffer patterned(const Rect& rect, uint32_t seed) {
  RegionFramebuffer fb(rect);
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      uint32_t h = (uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ (seed * 83492791u);
      if (h % 5 == 0) continue;  // some pixels stay empty
      size_t i = fb.index(x, y);
      fb.keys()[i] = fragmentKey(float(h % 1000) / 1000.0f, primitiveOrder(h % 4096, 0));
      fb.colours()[i] = glm::vec3(float(x), float(y), float(seed));
    }
  }
  return fb;
}

TEST_CASE("RegionFramebuffer: crops resolved back into an empty image reproduce it") {
  const Rect screen{0, 0, 37, 23};
  RegionFramebuffer full = patterned(screen, 1);
  for (const Rect& tile : tileRegions(37, 23, 8)) {
    RegionFramebuffer piece = crop(full, tile);
    CHECK(piece.rect() == tile);
    CHECK(piece.key(tile.x0, tile.y0) == full.key(tile.x0, tile.y0));
  }
  RegionFramebuffer assembled(screen);
  for (const Rect& strip : stripRegions(37, 23, 4)) resolveInto(crop(full, strip), assembled);
  CHECK(identical(assembled, full));
  // A crop reaching outside keeps only the inside part.
  CHECK(crop(full, Rect{30, 20, 50, 40}).rect() == Rect{30, 20, 37, 23});
  CHECK(crop(full, Rect{40, 0, 50, 5}).rect().empty());
}

TEST_CASE("RegionFramebuffer: depth compositing keeps the smaller key in any order") {
  const Rect screen{0, 0, 16, 16};
  RegionFramebuffer a = patterned(screen, 1), b = patterned(screen, 2), c = patterned(screen, 3);
  RegionFramebuffer abc(screen), cba(screen);
  for (const RegionFramebuffer* fb : {&a, &b, &c}) resolveInto(*fb, abc);
  for (const RegionFramebuffer* fb : {&c, &b, &a}) resolveInto(*fb, cba);
  CHECK(identical(abc, cba));
  int checked = 0, wrong = 0;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      uint64_t best = std::min({a.key(x, y), b.key(x, y), c.key(x, y)});
      wrong += abc.key(x, y) != best;
      if (!keyCovered(best)) continue;
      const RegionFramebuffer& winner = best == a.key(x, y) ? a : best == b.key(x, y) ? b : c;
      wrong += abc.colour(x, y) != winner.colour(x, y);
      ++checked;
    }
  }
  CHECK(checked > 200);
  CHECK(wrong == 0);
  image::Image img = toImage(abc);
  CHECK(img.width == 16);
  CHECK(img.at(3, 4) == abc.colour(3, 4));
}

TEST_CASE("RegionFramebuffer: depth keys order by depth, then primitive, then piece") {
  CHECK(fragmentKey(0.25f, primitiveOrder(900, 0)) < fragmentKey(0.5f, primitiveOrder(1, 0)));
  CHECK(fragmentKey(-2.0f, primitiveOrder(5, 0)) < fragmentKey(-1.0f, primitiveOrder(0, 0)));
  CHECK(fragmentKey(0.5f, primitiveOrder(1, 5)) < fragmentKey(0.5f, primitiveOrder(2, 0)));
  CHECK(fragmentKey(0.5f, primitiveOrder(2, 0)) < fragmentKey(0.5f, primitiveOrder(2, 1)));
  CHECK(fragmentKey(1e30f, primitiveOrder(kMaxPrimitives - 1, 7)) < kClearKey);
  CHECK(keyPrimitive(fragmentKey(0.125f, primitiveOrder(12345, 3))) == 12345);
  CHECK(keyDepth(fragmentKey(-0.375f, 0)) == -0.375f);
}

}  // namespace
}  // namespace pr::raster
