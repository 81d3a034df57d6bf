// Image files through OpenImageIO, the last step of every render and the first of every
// comparison. The format follows the extension: .exr keeps linear radiance (half or float),
// .png is the viewing copy (exposure, tone map, sRGB, 8 bits; see tone_map.h).
#pragma once

#include <filesystem>

#include "common/image/image.h"
#include "common/image/tone_map.h"

namespace pr::image {

struct WriteOptions {
  bool exrHalf = false;     // .exr: 16-bit half instead of 32-bit float channels
  DisplaySettings display;  // .png: exposure and tone map
};

// Writes `image` to `path`. The data goes to a temporary file in the same directory that is
// renamed over `path` only once complete, so a failed write leaves nothing behind.
// Throws pr::InputError for an extension other than .exr/.png (naming it), an empty image,
// or a path that cannot be written (naming the path).
void writeImage(const std::filesystem::path& path, const Image& image, const WriteOptions& options = {});

// Reads an image as linear RGB: EXR and Radiance HDR values as stored, 8/16-bit PNG and JPEG decoded from sRGB
// (the tone map is not inverted). Grey images are replicated to RGB, alpha is dropped.
// Throws pr::InputError naming the path when it is missing, unreadable or not .exr/.png.
Image readImage(const std::filesystem::path& path);

}  // namespace pr::image
