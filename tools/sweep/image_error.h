// How far an image is from a reference: the error figures of `parrender sweep` (RMSE, relative
// MSE, maximum error, and RMSE inside a mask such as the caustic region) and the x8 difference
// image of the seed's verification. Per channel, over linear radiance.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "common/image/image.h"

namespace pr::cli {

struct ImageError {
  double rmse = 0.0;         // sqrt(mean over pixels and channels of (a - r)^2)
  double relativeMse = 0.0;  // mean of (a - r)^2 / (r^2 + 1e-2), which weighs dark pixels fairly
  double maxError = 0.0;     // largest |a - r| of any channel
  double maskedRmse = 0.0;   // the RMSE over the pixels of the mask (0 when the mask is empty)
  std::size_t maskedPixels = 0;
};

// mask: one flag per pixel (empty = no mask). Images must have the same size (InputError).
ImageError imageError(const image::Image& image, const image::Image& reference, const std::vector<bool>& mask = {});

// "" when the images are bit-identical (every float of every pixel), else how they differ:
// "N pixels differ, largest by D" or "a different size".
std::string bitDifference(const image::Image& a, const image::Image& b);

// |image - reference| x scale per channel: the seed's "difference image multiplied by 8".
image::Image differenceImage(const image::Image& image, const image::Image& reference, float scale = 8.0f);

}  // namespace pr::cli
