// The boundary between image_io (file naming, validation, atomic replacement) and the image
// library that encodes and decodes pixels. OpenImageIO pulls in some 260 shared libraries whose
// relocation and constructors cost a process about half a second, so it lives in a module of
// its own (libparrender_image_codec.so, oiio_codec.cpp) that codec_loader.h opens on first use
// - or ahead of it, beside the scene load - and a command that touches no image never pays.
// Both sides are built by one build with one compiler: the interface is plain C++, errors are
// returned as text (image_io.cpp turns them into pr::InputError naming the file).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pr::image {

// Pixels as the codec decodes them: `channels` floats per pixel, rows top to bottom.
struct DecodedPixels {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> data;
};

class ImageCodec {
 public:
  virtual ~ImageCodec() = default;
  // Each returns "" on success, else the library's reason.
  // Linear RGB floats (w x h x 3) as OpenEXR, zip-compressed, half or float channels.
  virtual std::string writeExr(const std::string& path, int width, int height, const float* rgb, bool half) const = 0;
  // Display-encoded sRGB bytes (w x h x 3) as PNG.
  virtual std::string writePng(const std::string& path, int width, int height, const std::uint8_t* rgb) const = 0;
  // Any format the library reads, as floats (8/16-bit formats normalised to [0, 1]).
  virtual std::string read(const std::string& path, DecodedPixels& out) const = 0;
};

}  // namespace pr::image

// The module's one entry point (C linkage, found by dlsym): a codec that lives as long as the process.
extern "C" const pr::image::ImageCodec* parrender_image_codec();
