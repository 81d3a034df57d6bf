// `parrender render`: renders a bundled scene to PNG/EXR with a summary, writes run records;
// every bad input (file, method, option of the other family, range, extension) exits 2 with a
// message naming it.
#include <filesystem>
#include <string>

#include <doctest/doctest.h>

#include "common/image/image_io.h"
#include "raster/composite/compositor.h"
#include "raytrace/integrators/integrator.h"
#include "test_support.h"

using pr::test::cornell;
using pr::test::join;
using pr::test::quoted;
using pr::test::runParrender;

namespace {
}  // namespace

TEST_CASE("Render: image-space render writes the image, run record and a summary") {
  const auto dir = pr::test::scratchDir("render_ok");
  const auto out = dir / "c.exr";
  const auto metrics = dir / "run.json";
  const auto r = runParrender(join({"render ", cornell(), " -m image-space -o ", quoted(out),
                                     " --width 32 --height 24 --threads 2 --schedule spiral --integrator whitted --spp 1",
                                     " --metrics ", quoted(metrics)}));
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  CHECK(std::filesystem::exists(metrics));
  const pr::image::Image img = pr::image::readImage(out);
  CHECK(img.width == 32);
  CHECK(img.height == 24);
  CHECK(r.output.find("method image-space") != std::string::npos);
  CHECK(r.output.find("Mrays/s") != std::string::npos);
  CHECK(r.output.find("load imbalance") != std::string::npos);
}

TEST_CASE("Render: default output name is <scene stem>_<method>.png") {
  const auto dir = pr::test::scratchDir("render_default");
  // Run from the scratch directory so the default name lands there.
  const std::filesystem::path previous = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const auto r = runParrender(join({"render ", cornell(), " -m sequential --width 8 --height 8 --spp 1 --max-depth 2"}));
  std::filesystem::current_path(previous);
  INFO(r.output);
  CHECK(r.exitStatus == 0);
  CHECK(std::filesystem::exists(dir / "cornell_sequential.png"));
}

// Each case runs the program once (about half a second of start-up), one test case each.
#define RENDER_BAD_INPUT(TITLE, ARGS, EXPECT)                                  \
  TEST_CASE("Render: " TITLE " exits 2 naming it") {                           \
    const auto dir = pr::test::scratchDir("render_bad");                       \
    const std::string out = join({" -o ", quoted(dir / "x.png")});            \
    const auto r = runParrender(ARGS);                                         \
    INFO(r.output);                                                            \
    CHECK(r.exitStatus == 2);                                                  \
    CHECK(r.output.find(EXPECT) != std::string::npos);                         \
    CHECK_FALSE(std::filesystem::exists(dir / "x.png"));                       \
  }

RENDER_BAD_INPUT("a missing scene file", join({"render /nonexistent/scene.gltf", out}), "scene.gltf")
RENDER_BAD_INPUT("an unknown method", join({"render ", cornell(), " -m nonsense", out}), "nonsense")
RENDER_BAD_INPUT("an unknown integrator", join({"render ", cornell(), " --integrator photons", out}), "photons")
RENDER_BAD_INPUT("spp out of range", join({"render ", cornell(), " --spp 0", out}), "--spp")
RENDER_BAD_INPUT("max depth out of range", join({"render ", cornell(), " --max-depth 1000", out}), "--max-depth")
RENDER_BAD_INPUT("zero threads", join({"render ", cornell(), " --threads 0", out}), "--threads")
RENDER_BAD_INPUT("an unknown schedule", join({"render ", cornell(), " --schedule nope", out}), "nope")
RENDER_BAD_INPUT("a zero width", join({"render ", cornell(), " --width 0", out}), "--width")
RENDER_BAD_INPUT("an unknown camera", join({"render ", cornell(), " --camera 7", out}), "7")
RENDER_BAD_INPUT("an unsupported output extension", join({"render ", cornell(), " -o \"", (dir / "x.jpg").string(), "\""}), ".jpg")

TEST_CASE("Render: --integrator photonmap renders and reports its maps and cache") {
  const std::filesystem::path dir = pr::test::scratchDir("render_photonmap");
  const auto r = runParrender(join({"render ", cornell(), " --integrator photonmap --threads 2 --width 24 --height 18 --spp 1",
                                    " --photons 4000 --caustic-photons 2000 --gather 32 -o \"", (dir / "pm.png").string(), "\""}));
  INFO(r.output);
  CHECK(r.exitStatus == 0);
  CHECK(std::filesystem::exists(dir / "pm.png"));
  CHECK(r.output.find("photons stored: global ") != std::string::npos);
  CHECK(r.output.find("irradiance-cache records ") != std::string::npos);
  // The same through object partitioning: photon paths and gather rays travel as messages.
  const auto o = runParrender(join({"render ", cornell(), " -m object --integrator photonmap --threads 2 --width 24 --height 18",
                                    " --spp 1 --photons 4000 --caustic-photons 2000 --gather 32 -o \"", (dir / "pm_object.png").string(), "\""}));
  INFO(o.output);
  CHECK(o.exitStatus == 0);
  CHECK(std::filesystem::exists(dir / "pm_object.png"));
}

TEST_CASE("Render: the photon map takes 16 samples per pixel unless --spp says otherwise, the other integrators 4") {
  const std::filesystem::path dir = pr::test::scratchDir("render_default_spp");
  auto summary = [&](const std::string& options) {
    const auto r = runParrender(join({"render ", cornell(), " --threads 2 --width 8 --height 8 --photons 2000 --caustic-photons 1000",
                                      " --gather 16 ", options, " -o \"", (dir / "x.png").string(), "\""}));
    INFO(r.output);
    CHECK(r.exitStatus == 0);
    return r.output;
  };
  CHECK(summary("--integrator photonmap").find("integrator photonmap, spp 16,") != std::string::npos);
  CHECK(summary("--integrator photonmap --spp 4").find("integrator photonmap, spp 4,") != std::string::npos);
  const auto path = runParrender(join({"render ", cornell(), " --threads 2 --width 8 --height 8 --integrator path -o \"",
                                       (dir / "y.png").string(), "\""}));
  INFO(path.output);
  CHECK(path.output.find("integrator path, spp 4,") != std::string::npos);
}

TEST_CASE("Render: --help lists every integrator and compositor of their registries") {
  const auto r = runParrender("render --help");
  INFO(r.output);
  CHECK(r.exitStatus == 0);
  for (const pr::rt::IntegratorInfo& i : pr::rt::builtinIntegrators()) {
    CHECK(r.output.find(i.name) != std::string::npos);
    CHECK(r.output.find(i.description) != std::string::npos);
  }
  for (const pr::raster::CompositorInfo& c : pr::raster::compositors()) {
    CHECK(r.output.find(c.name) != std::string::npos);
    CHECK(r.output.find(c.description) != std::string::npos);
  }
}

RENDER_BAD_INPUT("an unknown integrator, listing the registry's", join({"render ", cornell(), " --integrator foo", out}),
                 "unknown integrator 'foo' (expected one of: whitted, path, photonmap)")
RENDER_BAD_INPUT("a photon-map option with another integrator", join({"render ", cornell(), " --integrator path --photons 1000", out}),
                 "--photons applies to --integrator photonmap, not path")
RENDER_BAD_INPUT("an unknown photon-map view", join({"render ", cornell(), " --integrator photonmap --view photons", out}), "--view")
RENDER_BAD_INPUT("an unknown compositor, listing the registry's",
                 join({"render ", cornell(), " -m sort-last --compositor foo", out}),
                 "unknown compositor 'foo' (expected one of: direct-send, binary-swap)")

TEST_CASE("Render: the image codec is opened only by commands that read or write an image") {
  // With the codec module pointed at a path that does not exist, commands that touch no image
  // run as usual (they never open it: start-up without OpenImageIO's libraries), and one that
  // writes an image fails with one message naming the module, leaving no output behind.
  const auto dir = pr::test::scratchDir("render_no_codec");
  const std::string missing = "PARRENDER_IMAGE_CODEC=" + quoted(dir / "absent.so") + " ";
  auto run = [&](const std::string& args) { return pr::test::runCommand(missing + "\"" + PARRENDER_EXE + "\" " + args); };
  CHECK(run("--help").exitStatus == 0);
  const auto info = run("info " + cornell());
  INFO(info.output);
  CHECK(info.exitStatus == 0);
  CHECK(run("generate cornell -o " + quoted(dir / "c.gltf")).exitStatus == 0);
  const auto out = dir / "c.png";
  const auto r = run(join({"render ", cornell(), " -m sort-middle -o ", quoted(out), " --width 16 --height 16 --threads 1"}));
  INFO(r.output);
  CHECK(r.exitStatus == 1);
  CHECK(r.output.find("image codec") != std::string::npos);
  CHECK(r.output.find("absent.so") != std::string::npos);
  CHECK(!std::filesystem::exists(out));
}
