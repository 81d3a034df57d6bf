// SortPoint: where a parallel raster pipeline redistributes its work to screen-region owners
// (Molnar et al. 1994; seed section 5.1.1). Sort-first sends scene primitives before geometry,
// sort-middle sends screen triangles between geometry and rasterization, sort-last sends
// shaded pixels after rasterization. All three call the stage functions of raster/stages and
// move data between PEs only through counted par::Channels (shared/DESIGN.md rules 1 and 4).
// The registry also holds sequential-raster, the sequential pipeline as one task on PE 0 with
// nothing sorted: the family's one-PE reference, renderable wherever a sort point is.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
#include "common/util/registry.h"
#include "raster/framebuffer.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/geometry.h"
#include "raster/stages/shade.h"

namespace pr::raster {

struct SortOptions {
  RegionStrategy regions = RegionStrategy::StaticTiles;  // --regions
  int tileSizePx = 32;                                   // --tile
  uint32_t batchSize = 4096;                             // scene triangles per geometry task
  std::string compositor = "direct-send";                // sort-last: --compositor
  bool sparse = false;                                   // sort-last: --sparse (covered pixels only)
  // A check for tests in one process (common/scene/poisoned_view.h): sort-first PEs read
  // geometry from a scene copy holding only the primitives they hold or were sent, so an
  // uncounted read shows. Across ranks every sort-first PE reads such a copy anyway.
  bool poisonForeignGeometry = false;
  // The RenderPlan's effects: shading skips textures, emission or direct light when they are
  // off, and the work not done is put in the run record (Plan/texture_evaluations_skipped,
  // Plan/emission_skipped, Plan/light_samples_skipped, per PE), as the ray tracers do.
  scene::EffectSet effects = scene::EffectSet::all();
  // --headlight: a scene without lights is lit from the eye instead of by its environment.
  bool headlight = false;
};

// The algorithm counters of the sort points, named per PE in the run record (Sort/...): the
// only way figures leave a sort point. Each renderFrame adds its frame's values per PE with
// Runtime::addCounter, so after N frames the record holds the totals the render command prints.
// Messages and bytes themselves are counted by the Channels; these say what they were.
//   sort-first:  Sort/primitives_routed     (primitive, owner) deliveries, the sender's own included
//                Sort/primitives_sent       deliveries to another PE (Channel messages carry them)
//                Sort/primitives_duplicated deliveries beyond the first owner of a primitive
//                Sort/primitives_migrated   primitives whose owner set changed since the last frame
//                Sort/pre_transforms        primitives pre-transformed to find their regions
//                Sort/geometry_repeated     primitives whose geometry an owner ran again
//   sort-middle: Sort/triangles_routed, Sort/triangles_sent, Sort/triangles_duplicated (the same
//                for screen triangles)
//   sort-last:   Sort/pixels_sent, Sort/composite_messages, Sort/composite_bytes (compositing)
// The names of sortPoint's counters ("sort-first" ...), in the order above.
const std::vector<std::string_view>& sortCounterNames(std::string_view sortPoint);
// Creates sortPoint's counters at zero for every PE (so a frame that adds nothing still
// records them). Called by each renderFrame on the controlling thread before its stages.
void declareSortCounters(std::string_view sortPoint, par::Runtime& runtime);

// One frame to render.
struct FrameInputs {
  const scene::Scene& scene;
  const FrameView& view;
  const SortOptions& options;
};

class SortPoint {
 public:
  virtual ~SortPoint() = default;
  // The shading counters of the last frame, per PE, reset by the call (the plan's skipped work).
  virtual std::vector<ShadeCounters> takeShadeCounters() = 0;
  // "sort-first" | "sort-middle" | "sort-last" | "sequential-raster" (no sort point: the reference)
  virtual std::string_view name() const = 0;
  // Whether renderFrame runs on a runtime whose PEs live in several ranks (mpirun): every rank
  // calls it (SPMD), each holding its own PEs' buffers, and what crosses ranks is a message.
  virtual bool runsAcrossRanks() const { return false; }
  // Renders one frame on the runtime's PEs into image (full screen), writing every pixel: what
  // it held before does not matter, so a caller can reuse one image from frame to frame.
  // Called by the controlling thread; runs one or more stages; may keep state between frames
  // (sort-first's frame coherence, binning storage). The image is assembled on the assembler
  // PE from counted region messages (frame_assembly.h); the frame's counters go to the run
  // record (Sort/..., Scene/... in the first frame), nothing else leaves.
  virtual void renderFrame(const FrameInputs& frame, par::Runtime& runtime, RegionFramebuffer& image) = 0;
};

std::unique_ptr<SortPoint> makeSortFirst();
std::unique_ptr<SortPoint> makeSortMiddle();
std::unique_ptr<SortPoint> makeSortLast();
// The sequential pipeline as one task on PE 0: the family's Ts, with no sort point (sequential.cpp).
std::unique_ptr<SortPoint> makeSequentialRaster();

// Registry: name -> factory -> description (feeds --help and validation).
using SortPointInfo = RegistryEntry<std::unique_ptr<SortPoint> (*)()>;
using SortPointRegistry = Registry<std::unique_ptr<SortPoint> (*)()>;
const SortPointRegistry& sortPoints();
// Throws pr::InputError naming the unknown method and listing the valid ones.
std::unique_ptr<SortPoint> makeSortPoint(std::string_view name);
bool isSortPoint(std::string_view name);

}  // namespace pr::raster
