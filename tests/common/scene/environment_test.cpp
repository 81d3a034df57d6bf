// Tests of the environment light (common/scene/environment.h): uniform radiance and density;
// an image's directions (its centre looks down -z, rotation about +y); the sampling density
// integrates to one and matches the samples; importance sampling and uniform sampling of the
// irradiance under a high-contrast map converge to the same mean; bad images are refused.
#include <doctest/doctest.h>

#include <cmath>

#include "common/scene/environment.h"
#include "common/util/error.h"

using namespace pr;

namespace {

constexpr float kPi = 3.14159265358979323846f;

// A dim sky with a small bright sun near the zenith towards +x, 64 x 32.
image::Image sunny() {
  image::Image img(64, 32, glm::vec3(0.2f, 0.3f, 0.5f));
  for (int y = 4; y < 7; ++y)
    for (int x = 40; x < 43; ++x) img.at(x, y) = glm::vec3(500.0f, 480.0f, 450.0f);
  return img;
}

glm::vec3 sphere(float u, float v) {
  const float z = 1.0f - 2.0f * u, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * v;
  return {r * std::cos(phi), z, r * std::sin(phi)};
}

}  // namespace

TEST_CASE("Environment: uniform radiance from every direction, density 1 / 4 pi") {
  const scene::Environment e = scene::Environment::uniform(glm::vec3(2.0f), "test");
  CHECK(e.radiance(glm::vec3(0, 1, 0)) == glm::vec3(2.0f));
  float pdf = 0.0f;
  const glm::vec3 d = e.sample(0.3f, 0.7f, pdf);
  CHECK(glm::length(d) == doctest::Approx(1.0f));
  CHECK(pdf == doctest::Approx(1.0f / (4.0f * kPi)));
  CHECK(e.pdf(d) == doctest::Approx(pdf));
}

TEST_CASE("Environment: an image's centre looks down -z and its rotation turns it about +y") {
  image::Image img(8, 4, glm::vec3(0.0f));
  img.at(4, 2) = glm::vec3(1.0f);  // u = 0.5..0.625, v = 0.5..0.75: just below the horizon, -z
  const scene::Environment e = scene::Environment::fromImage(img, 2.0f, 0.0f, "test");
  CHECK(e.radiance(glm::normalize(glm::vec3(0.2f, -0.3f, -1.0f))) == glm::vec3(2.0f));
  CHECK(e.radiance(glm::vec3(0.0f, 0.0f, 1.0f)) == glm::vec3(0.0f));
  const scene::Environment turned = scene::Environment::fromImage(img, 1.0f, kPi, "test");
  CHECK(turned.radiance(glm::normalize(glm::vec3(-0.2f, -0.3f, 1.0f))) == glm::vec3(1.0f));
}

TEST_CASE("Environment: the density integrates to one and importance sampling matches uniform sampling") {
  const scene::Environment e = scene::Environment::fromImage(sunny(), 1.0f, 0.3f, "sunny");
  // int pdf dw over the sphere, midpoint rule in (z, phi).
  double integral = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) integral += e.pdf(sphere((i + 0.5f) / n, (j + 0.5f) / (2 * n)));
  integral *= 4.0 * kPi / (double(n) * 2 * n);
  CHECK(integral == doctest::Approx(1.0).epsilon(0.01));
  // Irradiance on an upward surface, E = int L cos+ dw, by both estimators (stratified).
  double importance = 0.0, uniform = 0.0;
  const int m = 512;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const float u = (i + 0.5f) / m, v = (j + 0.5f) / m;
      float pdf;
      const glm::vec3 d = e.sample(u, v, pdf);
      importance += double(e.radiance(d).x) * std::max(0.0f, d.y) / double(pdf);
      const glm::vec3 s = sphere(u, v);
      uniform += double(e.radiance(s).x) * std::max(0.0f, s.y) * 4.0 * kPi;
    }
  importance /= double(m) * m;
  uniform /= double(m) * m;
  CHECK(importance == doctest::Approx(uniform).epsilon(0.02));
}

TEST_CASE("Environment: an empty image, negative or non-finite radiance and a bad strength are refused") {
  CHECK_THROWS_AS(scene::Environment::fromImage(image::Image(), 1.0f, 0.0f, "x"), InputError);
  image::Image bad(2, 1, glm::vec3(1.0f));
  bad.pixels[1] = glm::vec3(-1.0f);
  CHECK_THROWS_AS(scene::Environment::fromImage(bad, 1.0f, 0.0f, "x"), InputError);
  bad.pixels[1] = glm::vec3(std::nanf(""));
  CHECK_THROWS_AS(scene::Environment::fromImage(bad, 1.0f, 0.0f, "x"), InputError);
  CHECK_THROWS_AS(scene::Environment::fromImage(image::Image(2, 1), -1.0f, 0.0f, "x"), InputError);
}
