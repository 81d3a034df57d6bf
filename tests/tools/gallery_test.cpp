// `parrender gallery` run as a user would: a folder of models becomes one contact sheet (a row
// per model: screenshot | rasterizer | path tracer) and an index naming the rows; a model that
// fails to load is listed with its error; a folder without models exits 2.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/image/image_io.h"
#include "test_support.h"

using pr::test::join;
using pr::test::runParrender;

TEST_CASE("Gallery: a contact sheet with one row per model, the broken one listed with its error") {
  if (!pr::test::haveSharedScenes()) return;
  const std::filesystem::path dir = pr::test::scratchDir("gallery");
  const std::filesystem::path models = dir / "models";
  std::filesystem::create_directories(models);
  std::filesystem::create_directory_symlink(pr::test::sharedScenes() / "Box", models / "Box");
  { std::ofstream(models / "broken.gltf") << "{ not json"; }
  const std::filesystem::path out = dir / "out";
  const auto r = runParrender(join({"gallery \"", models.string(), "\" -o \"", out.string(), "\" --size 32 --spp 2"}));
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  // Box has three files (.gltf, .glb, embedded) plus the broken one: four rows of three cells,
  // one group (rows wrap into groups only when that keeps the sheet nearer square).
  const pr::image::Image sheet = pr::image::readImage(out / "contact_sheet.png");
  CHECK(sheet.width == 3 * 32);
  CHECK(sheet.height == 4 * 32);
  std::stringstream html;
  html << std::ifstream(out / "index.html").rdbuf();
  CHECK(html.str().find("Box.glb") != std::string::npos);
  // Files that share a name keep their own renders.
  CHECK(std::filesystem::exists(out / "Box_glTF_Binary_Box_sort-middle.png"));
  CHECK(std::filesystem::exists(out / "Box_glTF_Embedded_Box_image-space.png"));
  CHECK(html.str().find("not rendered") != std::string::npos);
  // The box's rasterized cell is not black.
  double sum = 0.0;
  for (int y = 0; y < 32; ++y)
    for (int x = 32; x < 64; ++x) sum += sheet.at(x, y).x;
  CHECK(sum > 10.0);
  CHECK_FALSE(std::filesystem::exists(dir / "out.partial"));
  // No models: exit 2.
  std::filesystem::create_directories(dir / "empty");
  const auto none = runParrender(join({"gallery \"", (dir / "empty").string(), "\" -o \"", (dir / "none").string(), "\""}));
  CHECK(none.exitStatus == 2);
  CHECK(none.output.find("no .gltf or .glb") != std::string::npos);
}
