// embree_anchor: the ray tracing anchor as a program. Loads a glTF scene, builds Embree's BVH
// (quality HIGH) and traces the camera's primary rays (one per pixel centre) with
// rtcIntersect1 on 1 and then P threads; prints one JSON line with the build time and Mrays/s.
//   embree_anchor SCENE.gltf [--width 1024] [--height 1024] [--threads 1,2] [--build-threads 1]
//                 [--repeat 3] [--camera SELECTOR]
// Exit status: 0 success, 2 bad input, 1 other failure.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "tools/bench/anchors/embree_anchor.h"

int main(int argc, char** argv) {
  CLI::App app{"embree_anchor: trace a glTF scene's primary rays with Intel Embree 3 (single rays, BVH quality "
               "HIGH) and print build time and Mrays/s as one JSON line"};
  std::string scenePath, cameraSelector;
  int width = 1024, height = 1024, buildThreads = 1, repeat = 3;
  std::vector<int> threadCounts{1, 2};
  app.add_option("scene", scenePath, "glTF scene (.gltf or .glb)")->required();
  app.add_option("--width", width, "image width in pixels (one ray each)")->check(CLI::Range(1, 16384))
      ->capture_default_str();
  app.add_option("--height", height, "image height in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  app.add_option("--threads", threadCounts, "tracing threads, one run per value (each traces a contiguous chunk)")
      ->check(CLI::Range(1, 256))->delimiter(',')->capture_default_str();
  app.add_option("--build-threads", buildThreads, "Embree worker threads for the BVH build (0 = all)")
      ->check(CLI::Range(0, 256))->capture_default_str();
  app.add_option("--repeat", repeat, "traces per thread count; the median is reported")->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--camera", cameraSelector, "camera: index, name or 'auto' (default: the file's first camera)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : pr::kExitBadInput;
  }

  try {
    const pr::scene::Scene scene = pr::scene::loadGltf(scenePath);
    const pr::scene::Camera camera = pr::scene::selectCamera(scene, cameraSelector, float(width) / float(height));
    const std::vector<pr::bench::RayIn> rays = pr::bench::primaryRays(camera, width, height);
    const pr::bench::EmbreeAnchor anchor(scene, buildThreads);
    nlohmann::json runs = nlohmann::json::array();
    size_t hits = 0;
    for (int threads : threadCounts) {
      std::vector<double> mrays, mraysCpu;
      for (int r = 0; r < repeat; ++r) {
        const pr::bench::TraceResult result = anchor.traceClosest(rays, threads);
        mrays.push_back(result.mraysPerSecond);
        mraysCpu.push_back(result.mraysPerCpuSecond);
        hits = result.hitCount;
      }
      std::sort(mrays.begin(), mrays.end());
      std::sort(mraysCpu.begin(), mraysCpu.end());
      runs.push_back({{"threads", threads},
                      {"mraysPerSecondMedian", mrays[mrays.size() / 2]},
                      {"mraysPerSecondMax", mrays.back()},
                      {"mraysPerCpuSecondMedian", mraysCpu[mraysCpu.size() / 2]}});
    }
    nlohmann::json line = {{"anchor", "embree"},
                           {"scene", scenePath},
                           {"triangles", anchor.triangleCount()},
                           {"buildThreads", buildThreads},
                           {"buildSeconds", anchor.buildSeconds()},
                           {"width", width},
                           {"height", height},
                           {"rays", rays.size()},
                           {"hitFraction", rays.empty() ? 0.0 : double(hits) / double(rays.size())},
                           {"primary", runs}};
    std::printf("%s\n", line.dump().c_str());
  } catch (const pr::InputError& e) {
    std::fprintf(stderr, "embree_anchor: error: %s\n", e.what());
    return pr::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "embree_anchor: failed: %s\n", e.what());
    return 1;
  }
  return 0;
}
