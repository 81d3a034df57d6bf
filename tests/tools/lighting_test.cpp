// The lighting options (tools/lighting.h) run as a user would: a model without lights renders
// lit in every ray tracer under the default environment, and the summary and info say so;
// --no-default-light leaves it black but for nothing; --env FILE lights it from an image;
// a missing environment file exits 2.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "common/image/image_io.h"
#include "test_support.h"

using pr::test::join;
using pr::test::runParrender;

namespace {

double meanOf(const std::filesystem::path& exr) {
  const pr::image::Image img = pr::image::readImage(exr);
  double sum = 0.0;
  for (const glm::vec3& p : img.pixels) sum += p.x + p.y + p.z;
  return sum / (3.0 * double(img.pixels.size()));
}

std::string duck() { return pr::test::quoted(pr::test::sharedScenes() / "Duck" / "glTF-Binary" / "Duck.glb"); }

}  // namespace

TEST_CASE("Lighting: a model without lights is lit by the default environment in every ray tracer") {
  if (!pr::test::haveSharedScenes()) return;
  const std::filesystem::path dir = pr::test::scratchDir("lighting");
  for (const char* method : {"sequential", "image-space", "image-space-cached", "object-space", "object"}) {
    CAPTURE(method);
    const auto r = runParrender(join({"render ", duck(), " -m ", method, " --threads 2 --width 24 --height 24 --spp 2 -o \"",
                                      (dir / (std::string(method) + ".exr")).string(), "\""}));
    INFO(r.output);
    REQUIRE(r.exitStatus == 0);
    CHECK(r.output.find("lighting: the default, a uniform white environment") != std::string::npos);
    CHECK(meanOf(dir / (std::string(method) + ".exr")) > 0.3);
  }
  const auto dark = runParrender(join({"render ", duck(), " --no-default-light --width 24 --height 24 --spp 2 -o \"",
                                       (dir / "dark.exr").string(), "\""}));
  INFO(dark.output);
  REQUIRE(dark.exitStatus == 0);
  CHECK(dark.output.find("lighting: none") != std::string::npos);
  CHECK(meanOf(dir / "dark.exr") == 0.0);
  // info applies the same lighting, so its plan is the render's.
  const auto info = runParrender(join({"info ", duck()}));
  CHECK(info.exitStatus == 0);
  CHECK(info.output.find("lighting: the default") != std::string::npos);
  CHECK(info.output.find("direct: on - the environment") != std::string::npos);
  const auto unlit = runParrender(join({"info ", duck(), " --no-default-light"}));
  CHECK(unlit.output.find("direct: off - no light") != std::string::npos);
}

TEST_CASE("Lighting: every sort point lights a model without lights by image-based lighting, bit-identically") {
  if (!pr::test::haveSharedScenes()) return;
  const std::filesystem::path dir = pr::test::scratchDir("lighting_raster");
  std::vector<pr::image::Image> images;
  for (const char* method : {"sort-first", "sort-middle", "sort-last"}) {
    CAPTURE(method);
    const std::filesystem::path out = dir / (std::string(method) + ".exr");
    const auto r = runParrender(join({"render ", duck(), " -m ", method, " --threads 2 --width 32 --height 32 -o \"",
                                      out.string(), "\""}));
    INFO(r.output);
    REQUIRE(r.exitStatus == 0);
    CHECK(r.output.find("the environment by image-based lighting") != std::string::npos);
    images.push_back(pr::image::readImage(out));
  }
  // The duck is lit (not only the white background shows).
  double duckSum = 0.0;
  int duckPixels = 0;
  for (const glm::vec3& p : images[0].pixels)
    if (p != glm::vec3(1.0f)) duckSum += p.x, ++duckPixels;
  CHECK(duckPixels > 20);
  CHECK(duckSum / duckPixels > 0.1);
  CHECK(images[1].pixels == images[0].pixels);
  CHECK(images[2].pixels == images[0].pixels);
  // --headlight: the old light from the eye, black background.
  const auto h = runParrender(join({"render ", duck(), " -m sort-middle --headlight --width 32 --height 32 -o \"",
                                    (dir / "headlight.exr").string(), "\""}));
  REQUIRE(h.exitStatus == 0);
  CHECK(h.output.find("a headlight") != std::string::npos);
  CHECK(pr::image::readImage(dir / "headlight.exr").pixels[0] == glm::vec3(0.0f));
}

TEST_CASE("Lighting: --env lights a scene from an equirectangular image, a missing file exits 2") {
  const std::filesystem::path dir = pr::test::scratchDir("lighting_env");
  pr::image::Image sky(16, 8, glm::vec3(0.5f));
  pr::image::writeImage(dir / "sky.exr", sky);
  const std::string cornell = pr::test::quoted(pr::test::sourceDir() / "scenes" / "cornell-diffuse.gltf");
  const auto plain = runParrender(join({"render ", cornell, " --width 24 --height 24 --spp 2 -o \"", (dir / "plain.exr").string(), "\""}));
  const auto lit = runParrender(join({"render ", cornell, " --env \"", (dir / "sky.exr").string(),
                                      "\" --env-strength 4 --width 24 --height 24 --spp 2 -o \"", (dir / "lit.exr").string(), "\""}));
  INFO(lit.output);
  REQUIRE(plain.exitStatus == 0);
  REQUIRE(lit.exitStatus == 0);
  CHECK(lit.output.find("lighting: the scene's lights and the environment") != std::string::npos);
  CHECK(meanOf(dir / "lit.exr") > meanOf(dir / "plain.exr"));
  const auto missing = runParrender(join({"render ", cornell, " --env /nonexistent/sky.exr -o \"", (dir / "x.png").string(), "\""}));
  CHECK(missing.exitStatus == 2);
  CHECK(missing.output.find("--env") != std::string::npos);
}
