// SortPoint: where a parallel raster pipeline redistributes its work to screen-region owners
// (Molnar et al. 1994; seed section 5.1.1). Sort-first sends scene primitives before geometry,
// sort-middle sends screen triangles between geometry and rasterization, sort-last sends
// shaded pixels after rasterization. All three call the stage functions of raster/stages and
// move data between PEs only through counted par::Channels (shared/DESIGN.md rules 1 and 4).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/scene/scene.h"
#include "common/util/registry.h"
#include "raster/framebuffer.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/geometry.h"

namespace pr::raster {

struct SortOptions {
  RegionStrategy regions = RegionStrategy::StaticTiles;  // --regions
  int tileSizePx = 32;                                   // --tile
  uint32_t batchSize = 4096;                             // scene triangles per geometry task
  std::string compositor = "direct-send";                // sort-last: --compositor
  bool sparse = false;                                   // sort-last: --sparse (covered pixels only)
};

// The algorithm counters of one frame (Sort/...), summed over PEs. Messages and bytes
// themselves are in the runtime's RunRecord (counted by the Channels); these say what they were.
struct SortCounters {
  // sort-first
  uint64_t primitivesRouted = 0;      // (primitive, owner) deliveries, the sender's own included
  uint64_t primitivesSent = 0;        // deliveries to another PE (Channel messages carry them)
  uint64_t primitivesDuplicated = 0;  // deliveries beyond the first owner of a primitive
  uint64_t primitivesMigrated = 0;    // sent to an owner that did not hold them last frame
  uint64_t preTransforms = 0;         // primitives pre-transformed to find their regions
  uint64_t geometryRepeated = 0;      // primitives whose geometry an owner ran again
  // sort-middle
  uint64_t trianglesRouted = 0;       // (screen triangle, owner) deliveries
  uint64_t trianglesSent = 0;         // deliveries to another PE
  uint64_t trianglesDuplicated = 0;   // deliveries beyond the first owner of a triangle
  // sort-last
  uint64_t pixelsSent = 0;            // pixels in compositing messages
  uint64_t compositeMessages = 0;
  uint64_t compositeBytes = 0;

  SortCounters& operator+=(const SortCounters& o);
};

// Puts each PE's counters of one frame in the run record as named per-PE counters
// (Sort/triangles_sent, ...; only those that belong to sortPoint, e.g. "sort-middle") and
// returns their sum over PEs, the frame's SortCounters. Runtime::addCounter adds, so after N
// frames the record holds the totals the render command prints. Called by each sort point's
// renderFrame on the controlling thread, after its last stage; perPe has one entry per PE.
SortCounters recordSortCounters(std::string_view sortPoint, const std::vector<SortCounters>& perPe,
                                par::Runtime& runtime);

// One frame to render.
struct FrameInputs {
  const scene::Scene& scene;
  const FrameView& view;
  const SortOptions& options;
};

class SortPoint {
 public:
  virtual ~SortPoint() = default;
  virtual std::string_view name() const = 0;  // "sort-first" | "sort-middle" | "sort-last"
  // Renders one frame on the runtime's PEs into image (full screen), writing every pixel: what
  // it held before does not matter, so a caller can reuse one image from frame to frame.
  // Called by the controlling thread; runs one or more stages; may keep state between frames
  // (sort-first's frame coherence, binning storage).
  virtual SortCounters renderFrame(const FrameInputs& frame, par::Runtime& runtime, RegionFramebuffer& image) = 0;
};

std::unique_ptr<SortPoint> makeSortFirst();
std::unique_ptr<SortPoint> makeSortMiddle();
std::unique_ptr<SortPoint> makeSortLast();

// Registry: name -> factory -> description (feeds --help and validation).
using SortPointInfo = RegistryEntry<std::unique_ptr<SortPoint> (*)()>;
using SortPointRegistry = Registry<std::unique_ptr<SortPoint> (*)()>;
const SortPointRegistry& sortPoints();
// Throws pr::InputError naming the unknown method and listing the valid ones.
std::unique_ptr<SortPoint> makeSortPoint(std::string_view name);
bool isSortPoint(std::string_view name);

}  // namespace pr::raster
