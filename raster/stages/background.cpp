// Background stage (see background.h).
#include "raster/stages/background.h"

#include <cmath>

#include <glm/gtc/matrix_inverse.hpp>

#include "raster/stages/shade.h"

namespace pr::raster {

bool showsEnvironment(const scene::Scene& scene, bool headlight) {
  return scene.environment && !litByHeadlight(scene, headlight);
}

void fillBackground(const FrameView& view, const scene::Environment& environment, RegionFramebuffer& fb) {
  const glm::mat4 inverse = glm::inverse(view.viewProjection);
  const Rect rect = fb.rect();
  PixelWindow w = fb.window();
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      const size_t i = w.index(x, y);
      if (keyCovered(w.keys[i])) continue;  // the final frame keeps keys, not triangle indices
      // The pixel centre in NDC (the viewport transform of geometry.cpp, inverted), unprojected
      // at two depths; z = 0.5 stays finite under an infinite far plane.
      const float nx = 2.0f * (float(x) + 0.5f) / float(view.width) - 1.0f;
      const float ny = 1.0f - 2.0f * (float(y) + 0.5f) / float(view.height);
      const glm::vec4 a = inverse * glm::vec4(nx, ny, -1.0f, 1.0f), b = inverse * glm::vec4(nx, ny, 0.5f, 1.0f);
      const glm::vec3 d = glm::vec3(b) / b.w - glm::vec3(a) / a.w;
      const float len = glm::length(d);
      w.colours[i] = len > 0.0f && std::isfinite(len) ? environment.radiance(d / len) : glm::vec3(0.0f);
    }
  }
}

}  // namespace pr::raster
