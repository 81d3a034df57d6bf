// The image codec module over OpenImageIO (see image_codec.h). Loaded by codec_loader.cpp; it
// is the only code that includes OpenImageIO headers.
#include "common/image/image_codec.h"

#include <OpenImageIO/imageio.h>

#include <memory>

namespace pr::image {
namespace {

std::string write(const std::string& path, const char* format, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                  const void* pixels) {
  auto out = OIIO::ImageOutput::create(format);
  if (!out) return std::string("OpenImageIO has no writer for ") + format;
  if (out->open(path, spec) && out->write_image(type, pixels) && out->close()) return "";
  std::string why = out->geterror();
  return why.empty() ? "the writer failed" : why;
}

class OiioCodec final : public ImageCodec {
 public:
  std::string writeExr(const std::string& path, int width, int height, const float* rgb, bool half) const override {
    OIIO::ImageSpec spec(width, height, 3, half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    return write(path, "openexr", spec, OIIO::TypeDesc::FLOAT, rgb);
  }

  std::string writePng(const std::string& path, int width, int height, const std::uint8_t* rgb) const override {
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    return write(path, "png", spec, OIIO::TypeDesc::UINT8, rgb);
  }

  std::string read(const std::string& path, DecodedPixels& out) const override {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
      const std::string why = OIIO::geterror();
      return why.empty() ? "the reader failed" : why;
    }
    const OIIO::ImageSpec& spec = in->spec();
    out.width = spec.width;
    out.height = spec.height;
    out.channels = spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1) return "";  // the caller names an empty image
    out.data.assign(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels), 0.0f);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, out.data.data())) {
      const std::string why = in->geterror();
      return why.empty() ? "the reader failed" : why;
    }
    in->close();
    return "";
  }
};

}  // namespace
}  // namespace pr::image

extern "C" const pr::image::ImageCodec* parrender_image_codec() {
  static const pr::image::OiioCodec codec;
  return &codec;
}
