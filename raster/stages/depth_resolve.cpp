// Depth resolve between framebuffers: per-pixel minimum of (depth, primitive order) keys.
// Called when region framebuffers are assembled into the image and, in sort-last, by the
// compositing step on the owner of each screen region (after the pixels arrived as messages).
#include "raster/stages/depth_resolve.h"

#include "raster/framebuffer.h"

namespace pr::raster {

void resolveInto(const RegionFramebuffer& src, RegionFramebuffer& dst) {
  Rect r = intersect(src.rect(), dst.rect());
  if (r.empty()) return;
  const uint64_t* srcKeys = src.keys();
  const glm::vec3* srcColours = src.colours();
  uint64_t* dstKeys = dst.keys();
  uint32_t* dstTriangles = dst.triangles();
  glm::vec3* dstColours = dst.colours();
  for (int y = r.y0; y < r.y1; ++y) {
    size_t s = src.index(r.x0, y);
    size_t d = dst.index(r.x0, y);
    for (int x = r.x0; x < r.x1; ++x, ++s, ++d) {
      if (!depthTest(dstKeys[d], srcKeys[s])) continue;
      dstKeys[d] = srcKeys[s];
      dstColours[d] = srcColours[s];
      // The source's triangle index refers to the source's own triangle list.
      dstTriangles[d] = kNoTriangle;
    }
  }
}

}  // namespace pr::raster
