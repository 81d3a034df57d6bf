// llvmpipe_anchor: the raster anchor as a program, so a benchmark can run llvmpipe once per
// LP_NUM_THREADS value (a process can use only one). Loads a glTF scene, draws it --frames
// times at --width x --height and prints one JSON line with the figures.
//   llvmpipe_anchor SCENE.gltf [--width 1920] [--height 1080] [--threads 0] [--frames 10]
//                   [--camera SELECTOR] [--output IMAGE.png]
// Exit status: 0 success, 2 bad input, 3 no usable llvmpipe on this machine, 1 other failure.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common/image/image.h"
#include "common/image/image_io.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "tools/bench/anchors/egl_context.h"
#include "tools/bench/anchors/llvmpipe_anchor.h"

int main(int argc, char** argv) {
  CLI::App app{"llvmpipe_anchor: draw a glTF scene with Mesa llvmpipe (EGL surfaceless, OpenGL ES 3) and print "
               "the median time per frame as one JSON line"};
  std::string scenePath, cameraSelector, outputPath;
  int width = 1920, height = 1080, threads = 0, frames = 10;
  app.add_option("scene", scenePath, "glTF scene (.gltf or .glb)")->required();
  app.add_option("--width", width, "image width in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  app.add_option("--height", height, "image height in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  app.add_option("--threads", threads, "LP_NUM_THREADS: 0 = single-threaded, n = n tile threads besides the front end")
      ->check(CLI::Range(0, 32))->capture_default_str();
  app.add_option("--frames", frames, "timed frames (after one warm-up frame)")->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--camera", cameraSelector, "camera: index, name or 'auto' (default: the file's first camera)");
  app.add_option("--output", outputPath, "also write the last frame (.png or .exr)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : pr::kExitBadInput;
  }

  try {
    const pr::scene::Scene scene = pr::scene::loadGltf(scenePath);
    const pr::scene::Camera camera = pr::scene::selectCamera(scene, cameraSelector, float(width) / float(height));
    const pr::bench::RasterAnchorResult r = pr::bench::renderWithLlvmpipe(scene, camera, width, height, threads, frames);
    if (!outputPath.empty()) {
      pr::image::Image image(width, height);
      for (size_t i = 0; i < image.size(); ++i)
        image.pixels[i] = glm::vec3(r.rgba[4 * i], r.rgba[4 * i + 1], r.rgba[4 * i + 2]) / 255.0f;
      pr::image::writeImage(outputPath, image);
    }
    nlohmann::json line = {
        {"anchor", "llvmpipe"},     {"scene", scenePath},          {"triangles", r.trianglesDrawn},
        {"width", width},           {"height", height},            {"threads", r.threads},
        {"frames", frames},         {"msPerFrameMedian", r.msPerFrameMedian}, {"frameMs", r.frameMs},
        {"cpuMsPerFrameMedian", r.cpuMsPerFrameMedian},
        {"uploadMs", r.uploadMs},   {"coveredPixels", r.coveredPixels},       {"renderer", r.renderer}};
    std::printf("%s\n", line.dump().c_str());
  } catch (const pr::InputError& e) {
    std::fprintf(stderr, "llvmpipe_anchor: error: %s\n", e.what());
    return pr::kExitBadInput;
  } catch (const pr::bench::AnchorUnavailable& e) {
    std::fprintf(stderr, "llvmpipe_anchor: llvmpipe unavailable: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "llvmpipe_anchor: failed: %s\n", e.what());
    return 1;
  }
  return 0;
}
