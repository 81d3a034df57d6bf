// Comparing a rendered image with a reference (a path-traced image, the P=1 render, a file):
// the error metrics that `compare` and the accuracy column of the report print, and the
// classic difference image |a - b| scaled by a factor (Jensen 1996, figure 7 uses x8).
#pragma once

#include "common/image/image.h"

namespace pr::image {

// relMSE denominator guard: mean of (a-b)^2 / (b^2 + eps) over all channels, with b the
// reference. 0.01 (as in Rousselle et al. 2011 and most denoising papers) keeps black
// reference pixels from dominating; it is ~1% of a mid-grey's squared value.
inline constexpr float kRelMseEpsilon = 0.01f;

// PSNR peak: radiance 1.0, the white of a clamp-tone-mapped display.
inline constexpr float kPsnrPeak = 1.0f;

struct ImageErrors {
  double rmse = 0.0;            // sqrt(mean over pixels and channels of (a-b)^2)
  double relMse = 0.0;          // mean of (a-b)^2 / (b^2 + kRelMseEpsilon), b the reference
  double psnrDb = 0.0;          // 10 log10(peak^2 / MSE), peak kPsnrPeak; +inf when identical
  double maxAbsError = 0.0;     // largest |a-b| over pixels and channels
};

// Compares `image` against `reference`. Both must have the same size (pr::InputError
// naming both sizes otherwise) and at least one pixel.
ImageErrors compareImages(const Image& image, const Image& reference);

// Per-channel |a - b| * scale, same size as the inputs (pr::InputError on mismatch).
Image differenceImage(const Image& a, const Image& b, float scale = 8.0f);

}  // namespace pr::image
