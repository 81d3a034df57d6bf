// The render methods of `parrender render -m NAME`: a registry (name -> family -> description
// -> function) over both families, the ray tracers (one method per raytrace Partition) and the
// rasterization pipelines. Family-specific options (ray: --integrator --spp --max-depth --seed
// --tile-size --adaptive --ray-batch; raster: --tile --regions --compositor ...) are registered with their
// family, with --integrator and --compositor checked against and described by their registries, so giving one to a method of the
// other family is an input error naming the option. Used by cmd_render.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/image/image.h"
#include "common/parallel/runtime.h"
#include "common/scene/camera.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
#include "common/util/registry.h"
#include "photonmap/photon_map_integrator.h"
#include "raytrace/partition/partition.h"

namespace pr::cli {

enum class MethodFamily { Ray, Raster };
std::string_view toString(MethodFamily family);  // "ray-tracing" | "rasterization"

// Options of the ray-tracing family.
struct RayOptions {
  std::string integrator = "path";
  int spp = 4;
  int maxDepth = 8;
  uint64_t seed = 1;
  int tileSizePx = 16;
  bool adaptive = false;
  int rayBatch = rt::kDefaultRayBatch;
  double cacheMb = double(rt::kDefaultCacheBytes) / 1048576.0;
  double dataLatencyUs = 0.0;
  bool noLatencyHiding = false;
  std::string prefetch = "profile";
  // --integrator photonmap's settings (--photons, --gather, --view, ...), and the options
  // that set them: giving one with another integrator is an input error.
  pm::PhotonMapSettings photonmap;
  std::string view = "full";
  std::vector<const CLI::Option*> photonOptions;
  const CLI::Option* sppOption = nullptr;  // --spp where the command has it (see samplesPerPixel)
};

// The samples per pixel a render takes: spp when set (by --spp, or by a command that has no
// such option), else the integrator's default: 16 for the photon map, whose pre-pass is a fixed
// cost that fewer samples leave noisier than it makes necessary, 4 for the others.
inline constexpr int kDefaultSpp = 4, kPhotonMapDefaultSpp = 16;
int samplesPerPixel(const RayOptions& ray);

// Options of the rasterization family (raster/sort/sort_point.h SortOptions, plus frames).
struct RasterOptions {
  int tileSizePx = 32;
  std::string regions = "static-tiles";
  std::string compositor = "direct-send";
  bool sparse = false;
  int frames = 1;
  bool orbit = false;
  bool headlight = false;
};

// Every family's options, filled by CLI11.
struct RenderSettings {
  RayOptions ray;
  RasterOptions raster;
};

// What a method needs for one render.
struct RenderRequest {
  const scene::Scene& scene;
  const scene::Camera& camera;
  int width = 0, height = 0;
  const RenderSettings& settings;
  const scene::RenderPlan& plan;  // the effects to simulate (analysis + --effects)
  par::Runtime& runtime;
  std::function<void(int64_t, int64_t)> progress;  // (tasks done, total), thread-safe
};

struct RenderOutcome {
  image::Image image;
  uint64_t rays = 0;     // rays traced (ray family), 0 otherwise
  std::string details;   // one extra summary line (family-specific), may be empty
  std::string effects;   // which of the plan's effects the method simulates, and what it skipped
};

// The trace job a ray-tracing method renders for the request: its options from the settings
// and its integrator from the program's registry. Throws pr::InputError for a photon-map option
// given with another integrator.
rt::TraceJob rayJobFor(const RenderRequest& request);

// Registry: name -> render function -> description, and the method's family.
struct MethodProperties {
  MethodFamily family = MethodFamily::Ray;
  // The family's one-PE reference (the sequential tracer, the sequential raster pipeline):
  // one task on one PE, the serial time Ts of the family's speed-ups; it runs at P = 1 only.
  bool reference = false;
};
using RenderFunction = RenderOutcome (*)(std::string_view name, const RenderRequest& request);
using RenderMethod = RegistryEntry<RenderFunction, MethodProperties>;
using RenderMethodRegistry = Registry<RenderFunction, MethodProperties>;

// Whether the named method is its family's one-PE reference (MethodProperties::reference).
bool isOnePeReference(std::string_view method);
// Every method, ray tracers first (from the raytrace partition registry).
const RenderMethodRegistry& renderMethods();
// Throws pr::InputError naming the unknown method and listing the valid ones.
const RenderMethod& findRenderMethod(std::string_view name);
// "name (family): description" lines for --help.
std::string describeRenderMethods();
// Whether the method runs on a runtime of several ranks (mpirun): a sort point or a ray
// tracer whose partition says so (raster::SortPoint::runsAcrossRanks,
// rt::Partition::runsAcrossRanks); and the names of those that do, comma-separated.
bool runsAcrossRanks(const RenderMethod& method);
std::string methodsAcrossRanks();

// Peak memory of a render, an upper estimate from its size alone (no scene): the frame
// (image, framebuffer, 8-bit output), a full framebuffer per PE for sort-last, and the rays
// in flight of the partitioned tracers, which hold every sample's camera ray at once. Checked
// against --max-memory before anything is loaded, so an absurd request fails at once.
uint64_t estimatedRenderBytes(const RenderMethod& method, int width, int height, int pes, int spp);
// Throws pr::InputError naming the request when its estimate exceeds the memory limit.
void checkRenderMemory(const RenderMethod& method, int width, int height, int pes, int spp);

// Family-specific options as registered on the command: checked after parsing.
using FamilyOptions = std::vector<std::pair<CLI::Option*, MethodFamily>>;
void addRayOptions(CLI::App& command, RenderSettings& settings, FamilyOptions& family);
void addRasterOptions(CLI::App& command, RenderSettings& settings, FamilyOptions& family);
// Throws pr::InputError when an option of another family than the method's was given.
void checkFamilyOptions(const RenderMethod& method, const FamilyOptions& family);

}  // namespace pr::cli
