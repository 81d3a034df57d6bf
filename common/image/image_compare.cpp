// Error metrics between an image and its reference and the scaled difference image (see
// image_compare.h). Runs once per comparison on the main thread; sums in double so that
// million-pixel images do not lose the small errors the metrics exist to show.
#include "common/image/image_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pr::image {
namespace {

void checkSameSize(const Image& a, const Image& b, const char* what) {
  if (a.width != b.width || a.height != b.height)
    throw InputError(std::string(what) + ": image sizes differ (" + std::to_string(a.width) + "x" +
                     std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                     ")");
}

}  // namespace

ImageErrors compareImages(const Image& image, const Image& reference) {
  checkSameSize(image, reference, "image comparison");
  if (image.empty()) throw InputError("image comparison: the images have no pixels");

  double sumSq = 0.0, sumRel = 0.0, maxAbs = 0.0;
  for (size_t i = 0; i < image.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      double a = image.pixels[i][c], b = reference.pixels[i][c];
      double d = a - b;
      sumSq += d * d;
      sumRel += d * d / (b * b + kRelMseEpsilon);
      maxAbs = std::max(maxAbs, std::abs(d));
    }
  }
  const double n = 3.0 * static_cast<double>(image.size());
  ImageErrors errors;
  const double mse = sumSq / n;
  errors.rmse = std::sqrt(mse);
  errors.relMse = sumRel / n;
  errors.psnrDb = mse > 0.0 ? 10.0 * std::log10(double(kPsnrPeak) * kPsnrPeak / mse)
                            : std::numeric_limits<double>::infinity();
  errors.maxAbsError = maxAbs;
  return errors;
}

Image differenceImage(const Image& a, const Image& b, float scale) {
  checkSameSize(a, b, "difference image");
  Image diff(a.width, a.height);
  for (size_t i = 0; i < a.size(); ++i) diff.pixels[i] = glm::abs(a.pixels[i] - b.pixels[i]) * scale;
  return diff;
}

}  // namespace pr::image
