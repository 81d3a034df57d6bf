// Error figures against a reference (see image_error.h).
#include "tools/sweep/image_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "common/util/error.h"

namespace pr::cli {

ImageError imageError(const image::Image& image, const image::Image& reference, const std::vector<bool>& mask) {
  if (image.width != reference.width || image.height != reference.height)
    throw InputError("image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                     " compared with a reference of " + std::to_string(reference.width) + "x" +
                     std::to_string(reference.height));
  if (!mask.empty() && mask.size() != image.pixels.size()) throw InputError("error mask does not match the image size");
  ImageError e;
  double squares = 0.0, relative = 0.0, maskedSquares = 0.0;
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    double pixel = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double r = reference.pixels[i][c];
      const double d = double(image.pixels[i][c]) - r;
      pixel += d * d;
      relative += d * d / (r * r + 1.0e-2);
      e.maxError = std::max(e.maxError, std::fabs(d));
    }
    squares += pixel;
    if (!mask.empty() && mask[i]) {
      maskedSquares += pixel;
      ++e.maskedPixels;
    }
  }
  const double n = 3.0 * double(std::max<std::size_t>(1, image.pixels.size()));
  e.rmse = std::sqrt(squares / n);
  e.relativeMse = relative / n;
  e.maskedRmse = e.maskedPixels ? std::sqrt(maskedSquares / (3.0 * double(e.maskedPixels))) : 0.0;
  return e;
}

image::Image differenceImage(const image::Image& image, const image::Image& reference, float scale) {
  imageError(image, reference);  // size check
  image::Image out(image.width, image.height);
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    out.pixels[i] = glm::abs(image.pixels[i] - reference.pixels[i]) * scale;
  return out;
}

std::string bitDifference(const image::Image& a, const image::Image& b) {
  if (a.width != b.width || a.height != b.height) return "a different size";
  std::size_t pixels = 0;
  float largest = 0.0f;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    if (std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(glm::vec3)) != 0) {
      ++pixels;
      const glm::vec3 d = glm::abs(a.pixels[i] - b.pixels[i]);
      largest = std::max({largest, d.x, d.y, d.z});
    }
  if (pixels == 0) return {};
  char text[96];
  std::snprintf(text, sizeof text, "%zu pixels differ, largest by %.3g", pixels, double(largest));
  return text;
}

}  // namespace pr::cli
