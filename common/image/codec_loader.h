// Opens the image codec module (image_codec.h) once per process: on first use, or ahead of it
// on a thread of its own, so a command that will write an image loads the library while it
// reads the scene instead of after it, and a command that touches no image (--help, info
// without --env, simulate, generate) never loads it.
#pragma once

#include "common/image/image_codec.h"

namespace pr::image {

// Starts opening the codec in the background and returns at once; later calls do nothing.
void preloadImageCodec();

// The codec, opened on the first call (or waiting for a preload under way). Throws
// std::runtime_error naming the module and where it was looked for when it cannot be opened.
// Thread-safe.
const ImageCodec& imageCodec();

}  // namespace pr::image
