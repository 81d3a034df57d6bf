// RasterRenderCommand: `parrender render -m sort-first|sort-middle|sort-last` with the raster
// options (--tile, --regions, --compositor, --sparse, --frames, --orbit): the three methods
// write the same image, and bad raster options are input errors (exit 2) naming the problem.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "common/image/image_io.h"

#include "test_support.h"

namespace pr::test {
namespace {

// The pixels of an EXR (its header holds the write time, so files are compared by pixels).
std::vector<float> readPixels(const std::filesystem::path& file) {
  const image::Image img = image::readImage(file);
  std::vector<float> v;
  for (const glm::vec3& c : img.pixels) v.insert(v.end(), {c.x, c.y, c.z});
  return v;
}

// Each parrender run costs about half a second of process start-up: two runs per case.
const std::string kCommon = " --width 48 --height 32 --quiet --threads 4 ";

std::string cornell() { return (sourceDir() / "scenes" / "cornell.gltf").string(); }

CommandResult render(const std::string& method, const std::string& options, const std::filesystem::path& out) {
  return runParrender("render \"" + cornell() + "\" -m " + method + kCommon + options + " -o \"" + out.string() + "\"");
}

TEST_CASE("RasterRenderCommand: sort-middle with dynamic tiles and sparse binary-swap sort-last agree") {
  const auto dir = scratchDir("raster_render_middle_last");
  CommandResult a = render("sort-middle", "--regions dynamic --tile 8", dir / "middle.exr");
  CommandResult b = render("sort-last", "--compositor binary-swap --sparse", dir / "last.exr");
  CHECK(a.exitStatus == 0);
  CHECK(b.exitStatus == 0);
  CHECK(a.output.find("triangles routed") != std::string::npos);
  CHECK(b.output.find("compositor binary-swap (sparse)") != std::string::npos);
  CHECK(readPixels(dir / "middle.exr").size() == 48u * 32u * 3u);
  CHECK(readPixels(dir / "middle.exr") == readPixels(dir / "last.exr"));
}

TEST_CASE("RasterRenderCommand: sort-first with static strips agrees with sort-middle") {
  const auto dir = scratchDir("raster_render_first");
  CHECK(render("sort-first", "--regions static-strips", dir / "first.exr").exitStatus == 0);
  CHECK(render("sort-middle", "", dir / "middle.exr").exitStatus == 0);
  CHECK(readPixels(dir / "first.exr") == readPixels(dir / "middle.exr"));
}

TEST_CASE("RasterRenderCommand: an orbit reports migrations and binary-swap needs a power-of-two P") {
  const auto dir = scratchDir("raster_render_orbit");
  CommandResult r = render("sort-first", "--frames 4 --orbit", dir / "orbit.png");
  CHECK(r.exitStatus == 0);
  CHECK(r.output.find("frames 4 (orbit)") != std::string::npos);
  CHECK(r.output.find("migrated") != std::string::npos);
  r = runParrender("render \"" + cornell() + "\" -m sort-last --threads 3 --compositor binary-swap --quiet -o \"" +
                   (dir / "x.png").string() + "\"");
  CHECK(r.exitStatus == 2);
  CHECK(r.output.find("power-of-two") != std::string::npos);
}

TEST_CASE("RasterRenderCommand: unknown region assignment and raster options on a ray tracer are input errors") {
  const auto dir = scratchDir("raster_render_errors");
  CommandResult r = render("sort-middle", "--regions diagonal", dir / "x.png");
  CHECK(r.exitStatus == 2);
  CHECK(r.output.find("--regions") != std::string::npos);
  r = render("image-space", "--compositor direct-send", dir / "x.png");
  CHECK(r.exitStatus == 2);
  CHECK(r.output.find("--compositor") != std::string::npos);
}

}  // namespace
}  // namespace pr::test
