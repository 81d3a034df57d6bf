#include "tests/fuzz/fuzz_inputs.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include "common/parallel/run_record.h"
#include "common/parallel/runtime.h"
#include "common/parallel/simulator.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "raster/framebuffer.h"
#include "raster/parallel_pipeline.h"
#include "raster/sort/sort_point.h"
#include "raster/stages/geometry.h"
#include "raytrace/partition/partition.h"
#include "tools/lighting.h"

namespace pr::fuzz {

namespace {

constexpr int kImageSize = 16;
// Bigger scenes are the loader target's; here they would only slow every execution down.
constexpr size_t kMaxRenderTriangles = 4096;

// Where the invariant broke, then abort: libFuzzer saves the input and reports the crash.
[[noreturn]] void broken(const char* what) {
  std::fprintf(stderr, "fuzz: broken invariant: %s\n", what);
  std::abort();
}

bool load(std::span<const uint8_t> bytes, scene::Scene& out) {
  try {
    scene::LoadOptions options;
    options.maxMemoryBytes = kLoadMemoryBytes;
    out = scene::loadGltfFromMemory(bytes, "input", options);
  } catch (const InputError&) {
    return false;
  }
  if (out.triangles.empty()) broken("a loaded scene without triangles");
  if (out.normals.size() != out.positions.size() || out.uvs.size() != out.positions.size())
    broken("vertex attribute arrays of different lengths");
  for (const scene::Triangle& t : out.triangles) {
    for (uint32_t v : t.v)
      if (v >= out.positions.size()) broken("a triangle index out of range");
    if (t.material >= out.materials.size()) broken("a material index out of range");
  }
  for (size_t i = 0; i < out.positions.size(); ++i) {
    const glm::vec3 p = out.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) broken("a non-finite position");
    if (!(std::abs(glm::length(out.normals[i]) - 1.0f) < 1e-3f)) broken("a normal that is not unit length");
  }
  return true;
}

void checkFinite(const image::Image& image, const char* method) {
  for (const glm::vec3& v : image.pixels)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) broken(method);
}

}  // namespace

bool loadInput(std::span<const uint8_t> bytes) {
  scene::Scene scene;
  return load(bytes, scene);
}

bool renderInput(std::span<const uint8_t> bytes) {
  scene::Scene scene;
  if (!load(bytes, scene) || scene.triangles.size() > kMaxRenderTriangles) return false;
  cli::applyLighting(scene, cli::LightingOptions{});
  const scene::Camera camera = scene::selectCamera(scene, "", 1.0f);
  const scene::RenderPlan plan = scene::analyzeEffects(scene, &camera);

  par::Runtime raster(par::RuntimeOptions{1, "demand", {}, false});
  std::unique_ptr<raster::SortPoint> sortPoint = raster::makeSortPoint("sort-middle");
  raster::SortOptions sortOptions;
  sortOptions.effects = plan.enabled();
  checkFinite(raster::toImage(raster::renderFrame(*sortPoint, scene, raster::makeFrameView(camera, kImageSize, kImageSize),
                                                  sortOptions, raster)),
              "a non-finite pixel from sort-middle");

  par::Runtime rays(par::RuntimeOptions{1, "demand", {}, false});
  rt::TraceOptions traceOptions;
  traceOptions.integrator.effects = plan.enabled();
  traceOptions.integrator.maxDepth = 6;
  const rt::TraceJob job{scene, camera, kImageSize, kImageSize, traceOptions};
  checkFinite(rt::renderRays(job, "image-space", rays).image, "a non-finite pixel from the path tracer");
  return true;
}

bool simulateInput(std::span<const uint8_t> bytes) {
  const std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  try {
    const auto first = text.find_first_not_of(" \t\r\n");
    const par::Workload workload = first != std::string::npos && text[first] == '{'
                                       ? par::workloadFromRecord(par::runRecordFromJsonText(text, "input"), "input")
                                       : par::workloadFromCostTable(text, "input");
    for (int pes : {1, 3, 64}) {
      par::SimOptions options;
      options.pes = pes;
      par::simulate(workload, workload.recordedPes > 0 ? "" : "demand", options);
    }
  } catch (const InputError&) {
    return false;
  }
  return true;
}

}  // namespace pr::fuzz
