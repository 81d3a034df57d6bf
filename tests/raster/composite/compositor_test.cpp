// Compositor: pixel packing (full and sparse) round-trips through a merge, a merge keeps the
// smaller depth key whatever the arrival order, and unknown compositor names are input errors.
#include <doctest/doctest.h>

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

TEST_CASE("Compositor: full and sparse messages carry the same pixels") {
  const RegionFramebuffer a = stripes(1, 0.5f, 2);
  for (bool sparse : {false, true}) {
    const PixelMessage m = packPixels(a, Rect{1, 1, 5, 4}, sparse);
    CHECK(m.rect == Rect{1, 1, 5, 4});
    CHECK(m.pixels() == (sparse ? 6u : 12u));  // half of the 4 x 3 pixels are covered
    CHECK(m.bytes(sparse) == m.pixels() * (sparse ? kSparsePixelBytes : kFullPixelBytes));
    RegionFramebuffer dst(Rect{0, 0, 6, 4});
    mergePixels(m, dst);
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 6; ++x) {
        const bool inside = Rect{1, 1, 5, 4}.contains(x, y);
        CHECK(dst.key(x, y) == (inside ? a.key(x, y) : kClearKey));
      }
  }
}

TEST_CASE("Compositor: merging keeps the nearer key in either order") {
  const RegionFramebuffer near = stripes(2, 0.25f, 1), far = stripes(1, 0.5f, 1);
  RegionFramebuffer ab(Rect{0, 0, 6, 4}), ba(Rect{0, 0, 6, 4});
  mergePixels(packPixels(near, near.rect(), true), ab);
  mergePixels(packPixels(far, far.rect(), false), ab);
  mergePixels(packPixels(far, far.rect(), true), ba);
  mergePixels(packPixels(near, near.rect(), false), ba);
  CHECK(identical(ab, ba));
  CHECK(identical(ab, near));
}

TEST_CASE("Compositor: names") {
  CHECK(makeCompositor("direct-send")->name() == "direct-send");
  CHECK(makeCompositor("binary-swap")->name() == "binary-swap");
  CHECK_THROWS_AS(makeCompositor("radix-k"), InputError);
}

}  // namespace
}  // namespace pr::raster
