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
#include "common/parallel/wire.h"
#include "common/scene/scene.h"

namespace pr::raster {

// One primitive as a distributed sort-first holds and sends it: its id, its index triple and
// material (scene::Triangle) and what the raster stages read of its three vertices: position,
// normal, uv, colour and tangent (zero where the scene has none of an attribute). A message of
// primitives is a vector of these, its encoding their bytes: 4 + 16 + 3 * (12 + 12 + 8 + 16 +
// 16) = 212 bytes each.
struct PrimitiveRecord {
  uint32_t id = 0;
  scene::Triangle triangle{};
  glm::vec3 position[3]{};
  glm::vec3 normal[3]{};
  glm::vec2 uv[3]{};
  glm::vec4 colour[3]{};
  glm::vec4 tangent[3]{};
};
inline constexpr size_t kPrimitiveBytes = sizeof(PrimitiveRecord);
static_assert(kPrimitiveBytes == 212, "PrimitiveRecord has padding: its bytes would not all be data");

// The record of scene triangle id, read from s.
PrimitiveRecord primitiveRecord(const scene::Scene& s, uint32_t id);
// Writes what r carries into view, a copy of the scene (the same arrays, indices and
// materials) in which the PE may hold only some primitives: the vertices' attributes of every
// array the view has.
void installPrimitive(scene::Scene& view, const PrimitiveRecord& r);

// A message of primitives (sort-first). Inside a rank it names them: their ids in `source`,
// the scene as the sender's rank loaded it, which every PE of that rank shares and nobody
// writes, so the message stays a move and a receiver reads the very bytes it is counted as.
// What leaves a rank is their data, a PrimitiveRecord each (Wire<PrimitiveBatch>), which the
// receiver installs into its own copy of the scene. Counted as the records either way.
struct PrimitiveBatch {
  const scene::Scene* source = nullptr;  // inside a rank: where ids are read
  std::vector<uint32_t> ids;             // with source
  std::vector<PrimitiveRecord> records;  // without: arrived from another rank

  size_t size() const { return source ? ids.size() : records.size(); }
  uint32_t id(size_t i) const { return source ? ids[i] : records[i].id; }
  PrimitiveRecord record(size_t i) const;
};

// Every primitive of the batch, the same.
void installPrimitives(scene::Scene& view, const PrimitiveBatch& batch);

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

namespace pr::par {
template <>
struct Wire<raster::PrimitiveBatch> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const raster::PrimitiveBatch& b) { return b.size() * raster::kPrimitiveBytes; }
  static void encode(const raster::PrimitiveBatch& b, WireWriter& w);
  static raster::PrimitiveBatch decode(WireReader& r);
};
}  // namespace pr::par
