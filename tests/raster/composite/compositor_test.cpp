// Compositor: fragment packing (full, and sparse = the drawn bounding rectangle only) round-trips
// through a merge that widens the receiver's drawn rectangle, a merge keeps the smaller depth
// key whatever the arrival order, and unknown compositor names are input errors.
#include <doctest/doctest.h>

#include <algorithm>

#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "raster/stages/depth_resolve.h"

namespace pr::raster {
namespace {

RegionFramebuffer stripes(uint32_t primitive, float depth, int every) {
  RegionFramebuffer fb(Rect{0, 0, 6, 4});
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) {
      if ((x + y) % every) continue;
      fb.keys()[fb.index(x, y)] = fragmentKey(depth + 0.01f * x, primitiveOrder(primitive, 0));
      fb.colours()[fb.index(x, y)] = glm::vec3(float(primitive), float(x), float(y));
    }
  return fb;
}

TEST_CASE("Compositor: full and sparse messages carry the same pixels, sparse only the drawn rectangle") {
  const RegionFramebuffer a = stripes(1, 0.5f, 2);
  const Rect region{1, 1, 5, 4}, drawn{0, 2, 3, 4};  // a's fragments drawn in rows 2..3, columns 0..2 only
  RegionFramebuffer only(a.rect());
  for (int y = drawn.y0; y < drawn.y1; ++y)
    for (int x = drawn.x0; x < drawn.x1; ++x) {
      only.keys()[only.index(x, y)] = a.key(x, y);
      only.colours()[only.index(x, y)] = a.colour(x, y);
    }
  for (bool sparse : {false, true}) {
    CAPTURE(sparse);
    const PixelMessage m = packPixels(only, region, drawn, sparse);
    CHECK(m.drawn == Rect{1, 2, 3, 4});
    CHECK(m.rect == (sparse ? Rect{1, 2, 3, 4} : region));
    CHECK(m.pixels() == (sparse ? 4u : 12u));
    CHECK(m.bytes() == kPixelHeaderBytes + m.pixels() * kPixelBytes);
    CHECK(par::encodeMessage(m).size() == m.bytes());  // what is counted is what travels
    const PixelMessage back = par::decodeMessage<PixelMessage>(par::encodeMessage(m));
    CHECK(back.rect == m.rect);
    CHECK(back.drawn == m.drawn);
    CHECK(back.keys == m.keys);
    par::Bytes truncated = par::encodeMessage(m);
    truncated.resize(truncated.size() - kPixelBytes);  // a key short of the rectangle
    CHECK_THROWS_AS(par::decodeMessage<PixelMessage>(truncated), par::WireError);
    PixelMessage outside = m;
    outside.drawn = Rect{0, 0, 9, 9};  // beyond the rectangle its keys cover
    CHECK_THROWS_AS(par::decodeMessage<PixelMessage>(par::encodeMessage(outside)), par::WireError);
    RegionFramebuffer dst(Rect{0, 0, 6, 4});
    Rect dstDrawn{5, 0, 6, 1};
    mergePixels(m, dst, dstDrawn);
    CHECK(dstDrawn == Rect{1, 0, 6, 4});
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 6; ++x) {
        const bool inside = m.drawn.contains(x, y);
        CHECK(dst.key(x, y) == (inside ? a.key(x, y) : kClearKey));
      }
  }
}

TEST_CASE("Compositor: merging keeps the nearer key in either order") {
  const RegionFramebuffer near = stripes(2, 0.25f, 1), far = stripes(1, 0.5f, 1);
  RegionFramebuffer ab(Rect{0, 0, 6, 4}), ba(Rect{0, 0, 6, 4});
  Rect abDrawn, baDrawn;
  mergePixels(packPixels(near, near.rect(), near.rect(), true), ab, abDrawn);
  mergePixels(packPixels(far, far.rect(), far.rect(), false), ab, abDrawn);
  mergePixels(packPixels(far, far.rect(), far.rect(), true), ba, baDrawn);
  mergePixels(packPixels(near, near.rect(), near.rect(), false), ba, baDrawn);
  // Keys travel, colours do not (the owner shades after compositing).
  auto sameKeys = [](const RegionFramebuffer& a, const RegionFramebuffer& b) {
    return std::equal(a.keys(), a.keys() + a.rect().area(), b.keys());
  };
  CHECK(sameKeys(ab, ba));
  CHECK(sameKeys(ab, near));
  CHECK(abDrawn == near.rect());
}

TEST_CASE("Compositor: names") {
  CHECK(makeCompositor("direct-send")->name() == "direct-send");
  CHECK(makeCompositor("binary-swap")->name() == "binary-swap");
  CHECK_THROWS_AS(makeCompositor("radix-k"), InputError);
}

}  // namespace
}  // namespace pr::raster
