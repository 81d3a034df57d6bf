// A primitive as a PE that holds only part of the geometry holds and sends it, and messages
// of them: what sort-first sends its region owners, and what the partitioned ray tracers send
// each owner of a share of the scene. A receiver with its own copy of the scene (NaN where it
// holds nothing, poisoned_view.h) installs what it receives, so it reads only what it holds
// or was sent.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"
#include "common/scene/scene.h"

namespace pr::scene {

// One primitive as it is sent: its id, its index triple and material (Triangle) and what
// geometry and shading read of its three vertices: position, normal, uv, colour and tangent
// (zero where the scene has none of an attribute): 4 + 16 + 3 * (12 + 12 + 8 + 16 + 16) = 212
// bytes.
struct PrimitiveRecord {
  uint32_t id = 0;
  Triangle triangle{};
  glm::vec3 position[3]{};
  glm::vec3 normal[3]{};
  glm::vec2 uv[3]{};
  glm::vec4 colour[3]{};
  glm::vec4 tangent[3]{};
};
inline constexpr size_t kPrimitiveBytes = sizeof(PrimitiveRecord);
static_assert(kPrimitiveBytes == 212, "PrimitiveRecord has padding: its bytes would not all be data");

// The record of scene triangle id, read from s.
PrimitiveRecord primitiveRecord(const Scene& s, uint32_t id);
// Writes what r carries into view, a copy of the scene (the same arrays, indices and
// materials) in which the PE may hold only some primitives: the vertices' attributes of every
// array the view has.
void installPrimitive(Scene& view, const PrimitiveRecord& r);

// A message of primitives. Inside a rank it names them: their ids in `source`, the scene as
// the sender's rank loaded it, which every PE of that rank shares and nobody writes, so the
// message stays a move and a receiver reads the very bytes it is counted as.
// What leaves a rank is their data, a PrimitiveRecord each (Wire<PrimitiveBatch>), which the
// receiver installs into its own copy of the scene. Counted as the records either way.
struct PrimitiveBatch {
  const Scene* source = nullptr;         // inside a rank: where ids are read
  std::vector<uint32_t> ids;             // with source
  std::vector<PrimitiveRecord> records;  // without: arrived from another rank

  size_t size() const { return source ? ids.size() : records.size(); }
  uint32_t id(size_t i) const { return source ? ids[i] : records[i].id; }
  PrimitiveRecord record(size_t i) const;
};

// Every primitive of the batch, the same.
void installPrimitives(Scene& view, const PrimitiveBatch& batch);

// Stage `stage`: PE 0, where the scene was loaded, sends every other PE the primitives it will
// hold (held(p)), one message each on "scene geometry" (kind data), counted as their records:
// sort-first's initial shares and the partitioned tracers' geometry. Returns, per PE of this
// rank, what it received (empty for PE 0 and for other ranks' PEs).
std::vector<PrimitiveBatch> sendPrimitiveShares(par::Runtime& rt, const Scene& s, std::string_view stage,
                                                const std::function<std::vector<uint32_t>(int)>& held);

// PE pe's own copy of the scene s (poisoned_view.h): NaN but for alsoHeld (replicated, such as
// the emitters), on PE 0 its share `held` (it loaded the scene), and the share it received,
// installed from the message. What the PE reads of geometry it was not given shows as NaN.
std::unique_ptr<Scene> shareView(const Scene& s, int pe, std::span<const uint32_t> held,
                                 std::span<const uint32_t> alsoHeld, const PrimitiveBatch& received);

}  // namespace pr::scene

namespace pr::par {
template <>
struct Wire<scene::PrimitiveBatch> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const scene::PrimitiveBatch& b) { return b.size() * scene::kPrimitiveBytes; }
  static void encode(const scene::PrimitiveBatch& b, WireWriter& w);
  static scene::PrimitiveBatch decode(WireReader& r);
};
}  // namespace pr::par
