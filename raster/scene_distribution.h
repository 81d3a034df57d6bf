// The scene's distribution to the raster PEs, recorded in the first frame a sort point renders
// on a runtime (shared/DESIGN.md rule 1). Sort-middle and sort-last run geometry batches under
// the runtime's schedule, so any PE may transform any triangle: the whole scene is replicated
// (world model), one broadcast per PE. Sort-first PEs start with contiguous shares of the
// primitives: the shading data (materials, textures, lights) is replicated as a broadcast and
// each share is sent from PE 0 (where the scene was loaded) as a counted data message.
// Each PE's geometry is put in the record as Scene/geometry_bytes_held and Scene/primitives_held.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "common/parallel/runtime.h"
#include "common/scene/primitive_batch.h"
#include "common/scene/scene.h"

namespace pr::raster {

using scene::PrimitiveBatch;
using scene::PrimitiveRecord;
using scene::kPrimitiveBytes;

// The scene's geometry arrays (vertices, triangles, objects) and everything else (shading data).
uint64_t geometryBytes(const scene::Scene& s);
uint64_t shadingDataBytes(const scene::Scene& s);

// Sort-first's initial share of PE pe: primitive ids [first, second), contiguous, in PE order.
std::pair<uint32_t, uint32_t> primitiveShare(uint32_t total, int pe, int pes);

// Kept by a sort point: says whether a frame is the first on this scene and runtime, the one
// that distributes the scene. Called by the controlling thread at the start of renderFrame.
class SceneDistribution {
 public:
  bool firstFrame(const scene::Scene& s, const par::Runtime& rt);

 private:
  const scene::Scene* scene_ = nullptr;
  const par::Runtime* runtime_ = nullptr;
  size_t triangles_ = 0;
};

// World model: the whole scene to every PE, counted as one broadcast per PE in the next stage.
void distributeReplicated(par::Runtime& rt, const scene::Scene& s);

// Sort-first: the shading data as a broadcast, then stage `stage` in which PE 0 (where the
// scene was loaded) sends every other PE its primitiveShare as one message (channel "scene
// geometry", kind data); PE 0 keeps its own share. Returns, per PE of this rank, what it
// received (empty for PE 0 and for PEs of other ranks).
std::vector<PrimitiveBatch> distributeShares(par::Runtime& rt, const scene::Scene& s, std::string_view stage);

}  // namespace pr::raster
