// Tests of common/image/image_compare.cpp: every metric on small images whose values are
// worked out by hand in the comments, the difference image, and the size-mismatch error.
#include <doctest/doctest.h>

#include <cmath>

#include "common/image/image_compare.h"

using pr::image::Image;

namespace {

// Reference: two pixels (0.5, 0.5, 0.5) and (1, 0, 0.25).
// Image:     two pixels (0.5, 0.5, 0.5) and (0, 0, 0.75); differences 0,0,0, -1,0,+0.5.
Image reference() {
  Image r(2, 1);
  r.at(0, 0) = glm::vec3(0.5f);
  r.at(1, 0) = glm::vec3(1.0f, 0.0f, 0.25f);
  return r;
}
Image rendered() {
  Image a(2, 1);
  a.at(0, 0) = glm::vec3(0.5f);
  a.at(1, 0) = glm::vec3(0.0f, 0.0f, 0.75f);
  return a;
}

}  // namespace

TEST_CASE("ImageCompare: metrics of a known pair match hand-computed values") {
  auto e = pr::image::compareImages(rendered(), reference());
  // Squared errors over 6 channels: 1 + 0.25 = 1.25 -> MSE = 1.25 / 6 = 0.208333.
  CHECK(e.rmse == doctest::Approx(std::sqrt(1.25 / 6.0)));
  // relMSE: 1/(1+0.01) + 0.25/(0.0625+0.01) = 0.990099 + 3.448276 = 4.438375; / 6 = 0.739729.
  CHECK(e.relMse == doctest::Approx((1.0 / 1.01 + 0.25 / 0.0725) / 6.0));
  CHECK(e.relMse == doctest::Approx(0.739729).epsilon(1e-5));
  // PSNR, peak 1: 10 log10(1 / 0.208333) = 6.812 dB.
  CHECK(e.psnrDb == doctest::Approx(6.8124).epsilon(1e-4));
  CHECK(e.maxAbsError == doctest::Approx(1.0));
}

TEST_CASE("ImageCompare: relMSE uses the second argument as the reference") {
  // Swapping the arguments changes the denominators: b = (0,0,0.75) now.
  auto e = pr::image::compareImages(reference(), rendered());
  // 1/(0+0.01) + 0.25/(0.5625+0.01) = 100 + 0.436681 = 100.436681; / 6 = 16.739447.
  CHECK(e.relMse == doctest::Approx(16.739447).epsilon(1e-6));
  CHECK(e.rmse == doctest::Approx(std::sqrt(1.25 / 6.0)));  // symmetric
}

TEST_CASE("ImageCompare: identical images have zero error and infinite PSNR") {
  auto e = pr::image::compareImages(reference(), reference());
  CHECK(e.rmse == 0.0);
  CHECK(e.relMse == 0.0);
  CHECK(e.maxAbsError == 0.0);
  CHECK(std::isinf(e.psnrDb));
  CHECK(e.psnrDb > 0.0);
}

TEST_CASE("ImageCompare: difference image is |a-b| times the scale") {
  Image d = pr::image::differenceImage(rendered(), reference(), 8.0f);
  REQUIRE(d.width == 2);
  REQUIRE(d.height == 1);
  CHECK(d.at(0, 0) == glm::vec3(0.0f));
  CHECK(d.at(1, 0) == glm::vec3(8.0f, 0.0f, 4.0f));  // |-1| * 8, 0, |0.5| * 8
  Image d1 = pr::image::differenceImage(reference(), rendered(), 1.0f);
  CHECK(d1.at(1, 0) == glm::vec3(1.0f, 0.0f, 0.5f));  // symmetric, unscaled
}

TEST_CASE("ImageCompare: size mismatch is an InputError naming both sizes") {
  Image small(2, 1), other(1, 2);
  try {
    pr::image::compareImages(small, other);
    FAIL("expected InputError");
  } catch (const pr::InputError& e) {
    std::string what = e.what();
    CHECK(what.find("2x1") != std::string::npos);
    CHECK(what.find("1x2") != std::string::npos);
  }
  CHECK_THROWS_AS(pr::image::differenceImage(small, other), pr::InputError);
  CHECK_THROWS_AS(pr::image::compareImages(Image(), Image()), pr::InputError);
}
