// Tests of common/image/image_io.cpp: EXR and PNG round trips, format by extension,
// and the error paths (bad extension, unwritable path, missing file) with nothing left behind.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/image/image_io.h"
#include "test_support.h"

namespace fs = std::filesystem;
using pr::image::Image;

namespace {

// A 5x3 image with distinct values per pixel and channel, including HDR (> 1) and tiny values,
// so a transposed, flipped or channel-swapped read-back cannot pass.
Image testImage() {
  Image image(5, 3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      image.at(x, y) = glm::vec3(0.1f * x + 0.013f, 0.3f * y + 0.0007f, 0.05f * (x + y) + 2.5f * (x == 4 && y == 0));
  return image;
}

size_t fileCount(const fs::path& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST_CASE("ImageIo: EXR float round trip is exact") {
  auto dir = pr::test::scratchDir("image_io_exr");
  Image image = testImage();
  pr::image::writeImage(dir / "a.exr", image);
  Image back = pr::image::readImage(dir / "a.exr");
  REQUIRE(back.width == 5);
  REQUIRE(back.height == 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) CHECK(back.at(x, y) == image.at(x, y));
  CHECK(fileCount(dir) == 1);  // the temporary file was renamed, not left beside it
}

TEST_CASE("ImageIo: EXR half keeps values to half precision") {
  auto dir = pr::test::scratchDir("image_io_exr_half");
  Image image = testImage();
  pr::image::WriteOptions options;
  options.exrHalf = true;
  pr::image::writeImage(dir / "h.exr", image, options);
  Image back = pr::image::readImage(dir / "h.exr");
  REQUIRE(back.size() == image.size());
  bool anyInexact = false;
  for (size_t i = 0; i < image.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      float v = image.pixels[i][c];
      // Half has an 11-bit significand: relative error <= 2^-11 for normal values.
      CHECK(std::abs(back.pixels[i][c] - v) <= std::abs(v) * 0x1p-11f + 1e-7f);
      anyInexact |= back.pixels[i][c] != v;
    }
  CHECK(anyInexact);  // proves the file really holds half, not float
}

TEST_CASE("ImageIo: PNG round trip within 8-bit quantisation, top row first") {
  auto dir = pr::test::scratchDir("image_io_png");
  Image image(4, 2);
  for (int x = 0; x < 4; ++x) {
    image.at(x, 0) = glm::vec3(x / 3.0f, 0.5f, 0.02f);
    image.at(x, 1) = glm::vec3(0.0f, 1.0f - x / 3.0f, 0.9f);
  }
  pr::image::writeImage(dir / "a.png", image);
  Image back = pr::image::readImage(dir / "a.png");
  REQUIRE(back.width == 4);
  REQUIRE(back.height == 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) {
        float v = image.at(x, y)[c];
        // Half an 8-bit step in sRGB space, mapped back to linear through the curve's slope.
        float lo = pr::image::srgbDecode(pr::image::srgbEncode(v) - 0.5f / 255.0f);
        float hi = pr::image::srgbDecode(pr::image::srgbEncode(v) + 0.5f / 255.0f);
        CHECK(back.at(x, y)[c] >= lo - 1e-6f);
        CHECK(back.at(x, y)[c] <= hi + 1e-6f);
      }
}

TEST_CASE("ImageIo: PNG clamps radiance above 1 and exposure scales by stops") {
  auto dir = pr::test::scratchDir("image_io_png_exposure");
  Image image(2, 1);
  image.at(0, 0) = glm::vec3(4.0f);
  image.at(1, 0) = glm::vec3(0.25f);
  pr::image::WriteOptions options;
  options.display.exposureStops = 1.0f;  // x2: 0.25 -> 0.5
  pr::image::writeImage(dir / "e.png", image, options);
  Image back = pr::image::readImage(dir / "e.png");
  CHECK(back.at(0, 0).x == doctest::Approx(1.0f));
  CHECK(back.at(1, 0).y == doctest::Approx(0.5f).epsilon(0.01));
}

TEST_CASE("ImageIo: extension is case-insensitive and anything else is an InputError naming it") {
  auto dir = pr::test::scratchDir("image_io_ext");
  Image image = testImage();
  pr::image::writeImage(dir / "upper.EXR", image);
  CHECK(pr::image::readImage(dir / "upper.EXR").at(1, 1) == image.at(1, 1));
  try {
    pr::image::writeImage(dir / "a.jpg", image);
    FAIL("expected InputError");
  } catch (const pr::InputError& e) {
    CHECK(std::string(e.what()).find("'.jpg'") != std::string::npos);
  }
  CHECK_THROWS_AS(pr::image::writeImage(dir / "noext", image), pr::InputError);
  CHECK_THROWS_AS(pr::image::readImage(dir / "a.tiff"), pr::InputError);
  CHECK_FALSE(fs::exists(dir / "a.jpg"));
}

TEST_CASE("ImageIo: unwritable path is an InputError naming it and leaves nothing behind") {
  auto dir = pr::test::scratchDir("image_io_unwritable");
  Image image = testImage();
  // A directory that does not exist, and a "directory" that is a regular file: both fail
  // whatever the user's permissions are.
  fs::path missing = dir / "no_such_dir" / "out.exr";
  try {
    pr::image::writeImage(missing, image);
    FAIL("expected InputError");
  } catch (const pr::InputError& e) {
    CHECK(std::string(e.what()).find(missing.string()) != std::string::npos);
  }
  std::ofstream(dir / "plainfile") << "x";
  CHECK_THROWS_AS(pr::image::writeImage(dir / "plainfile" / "out.png", image), pr::InputError);
  CHECK(fileCount(dir) == 1);  // only plainfile: no temporary left
}

TEST_CASE("ImageIo: failed write leaves an existing file untouched") {
  auto dir = pr::test::scratchDir("image_io_keep");
  Image image = testImage();
  pr::image::writeImage(dir / "keep.exr", image);
  CHECK_THROWS_AS(pr::image::writeImage(dir / "keep.exr", Image()), pr::InputError);
  CHECK(pr::image::readImage(dir / "keep.exr").at(2, 1) == image.at(2, 1));
}

TEST_CASE("ImageIo: reading a missing or corrupt file is an InputError naming it") {
  auto dir = pr::test::scratchDir("image_io_read_errors");
  try {
    pr::image::readImage(dir / "none.exr");
    FAIL("expected InputError");
  } catch (const pr::InputError& e) {
    CHECK(std::string(e.what()).find("none.exr") != std::string::npos);
  }
  std::ofstream(dir / "junk.png") << "this is not a png";
  CHECK_THROWS_AS(pr::image::readImage(dir / "junk.png"), pr::InputError);
}
