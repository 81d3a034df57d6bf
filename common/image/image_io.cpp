// Image files (see image_io.h): EXR for linear radiance, PNG for viewing. The pixels are
// encoded and decoded by the image codec module (OpenImageIO, image_codec.h), opened on first use.
// Called once per render on the main thread after the PEs have finished, and by `compare`.
#include "common/image/image_io.h"

#include "common/image/codec_loader.h"
#include "common/util/atomic_file.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <string>
#include <system_error>
#include <unistd.h>

namespace pr::image {
namespace {

namespace fs = std::filesystem;

enum class Format { Exr, Png };

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

Format formatOf(const fs::path& path) {
  std::string ext = lowerExtension(path);
  if (ext == ".exr") return Format::Exr;
  if (ext == ".png") return Format::Png;
  throw InputError("image file '" + path.string() + "': unsupported extension '" + path.extension().string() +
                   "' (expected .exr or .png)");
}

}  // namespace

void writeImage(const fs::path& path, const Image& image, const WriteOptions& options) {
  const Format format = formatOf(path);
  if (image.empty() || image.width <= 0 || image.height <= 0)
    throw InputError("image file '" + path.string() + "': nothing to write (empty image)");
  PR_CHECK(image.pixels.size() == static_cast<size_t>(image.width) * static_cast<size_t>(image.height),
           "pixel count does not match width * height");

  // The temporary keeps the directory (so the rename is atomic) but not the extension, so the
  // format is named explicitly below rather than guessed from the file name.
  TempFile temp(path, "image file");

  const ImageCodec& codec = imageCodec();
  const size_t count = image.pixels.size();
  std::string why;
  if (format == Format::Exr) {
    // glm::vec3 is three packed floats, so the pixel array is the interleaved RGB buffer.
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
    why = codec.writeExr(temp.path().string(), image.width, image.height, &image.pixels.data()->x, options.exrHalf);
  } else {
    std::vector<uint8_t> bytes(count * 3);
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) bytes[3 * i + c] = toDisplay8(image.pixels[i][c], options.display);
    why = codec.writePng(temp.path().string(), image.width, image.height, bytes.data());
  }
  if (!why.empty()) throw InputError("cannot write image file '" + path.string() + "': " + why);

  temp.commit();
}

Image readImage(const fs::path& path) {
  // Radiance HDR (environment maps) reads as linear radiance, like EXR; JPEG (reference
  // screenshots) is sRGB-encoded, like PNG.
  const std::string ext = lowerExtension(path);
  const Format format = ext == ".hdr" ? Format::Exr : ext == ".jpg" || ext == ".jpeg" ? Format::Png : formatOf(path);
  if (!fs::is_regular_file(path)) throw InputError("image file '" + path.string() + "' does not exist");

  DecodedPixels decoded;
  if (const std::string why = imageCodec().read(path.string(), decoded); !why.empty())
    throw InputError("cannot read image file '" + path.string() + "': " + why);
  const int channels = decoded.channels;
  if (decoded.width <= 0 || decoded.height <= 0 || channels < 1)
    throw InputError("image file '" + path.string() + "' has no pixels");
  const std::vector<float>& data = decoded.data;

  Image image(decoded.width, decoded.height);
  // Channels: 1 or 2 (grey, grey+alpha) replicate the first; 3+ take R, G, B and drop the rest.
  const bool grey = channels < 3;
  for (size_t i = 0; i < image.size(); ++i) {
    const float* p = &data[i * channels];
    glm::vec3 v = grey ? glm::vec3(p[0]) : glm::vec3(p[0], p[1], p[2]);
    if (format == Format::Png) v = glm::vec3(srgbDecode(v.x), srgbDecode(v.y), srgbDecode(v.z));
    image.pixels[i] = v;
  }
  return image;
}

}  // namespace pr::image
