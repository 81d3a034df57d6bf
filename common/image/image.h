// Image: the float RGB framebuffer every renderer writes into and every output path reads.
// Pixels hold linear radiance, row 0 is the top row of the picture. Written and read by
// image_io.cpp (EXR for radiance, PNG for viewing); compared by image_compare.cpp.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "common/util/error.h"

namespace pr::image {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;  // width * height, row-major, row 0 = top

  Image() = default;
  Image(int w, int h, glm::vec3 fill = glm::vec3(0.0f))
      : width(w), height(h), pixels(checkedCount(w, h), fill) {}

  bool empty() const { return pixels.empty(); }
  size_t size() const { return pixels.size(); }

  glm::vec3& at(int x, int y) {
    PR_DCHECK(x >= 0 && x < width && y >= 0 && y < height, "pixel outside the image");
    return pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
  }
  const glm::vec3& at(int x, int y) const {
    PR_DCHECK(x >= 0 && x < width && y >= 0 && y < height, "pixel outside the image");
    return pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
  }

 private:
  static size_t checkedCount(int w, int h) {
    PR_CHECK(w >= 0 && h >= 0, "negative image size");
    return static_cast<size_t>(w) * static_cast<size_t>(h);
  }
};

}  // namespace pr::image
