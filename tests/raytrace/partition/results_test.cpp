// Image assembly in the partitioned tracers: every PE's film contributions travel to the
// assembler (PE 0) as counted film-block messages in an "assemble" stage, the emitters are
// counted in the broadcast, and the image stays the sequential one.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "raytrace/integrators/integrator.h"
#include "raytrace/partition/film_assembly.h"
#include "raytrace/partition/partitioned.h"
#include "tests/raytrace/partition/partitioned_test_support.h"

namespace pr::test {
namespace {

// A 32 x 32 image in 8 x 8 tiles: 16 tiles of 64 pixels. A PE other than the assembler sends
// one block per tile it shaded anything in: a 16-byte rectangle and 3 int64 sums per pixel.
constexpr int kSize = 32, kTiles = 16;
constexpr uint64_t kBlockBytes = 16 + 24 * 64;

template <class P>
void checkAssembly(P& partition, int pes) {
  const scene::Scene s = scene::loadGltf(bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  const rt::TraceOptions opt = partitionedOptions(rt::IntegratorKind::Path, 2);
  const PartitionedRun run = renderPartitioned(partition, s, cam, kSize, kSize, opt, pes, "balanced");
  CHECK(run.image.pixels == renderSequential(s, cam, kSize, kSize, opt).pixels);

  const par::StageRecord* assemble = nullptr;
  for (const par::StageRecord& st : run.record.stages)
    if (st.name == "assemble") assemble = &st;
  REQUIRE(assemble != nullptr);
  CHECK(assemble->schedule == par::kOwnerPinnedSchedule);
  uint64_t messages = 0;
  for (int p = 0; p < pes; ++p) {
    const par::PeStageRecord& r = assemble->pes[size_t(p)];
    if (p == rt::kAssemblerPe) {
      CHECK(r.messagesSent == 0u);
      continue;
    }
    // The Cornell box fills the frame and every PE shades somewhere in it; no PE sends a
    // tile twice, and nothing goes anywhere but the assembler.
    CHECK(r.messagesSent > 0u);
    CHECK(r.messagesSent <= uint64_t(kTiles));
    CHECK(r.bytesSent == r.messagesSent * kBlockBytes);
    messages += r.messagesSent;
  }
  CHECK(assemble->pes[size_t(rt::kAssemblerPe)].messagesReceived == messages);
  REQUIRE(assemble->channels.size() == 1u);
  CHECK(assemble->channels[0].kind == "results");
  CHECK(assemble->channels[0].bytes == messages * kBlockBytes);

  // The emitters are replicated: counted per PE and inside the trace stage's broadcast.
  const rt::LightSampler lights(s);
  const uint64_t emitters = rt::emitterBytes(lights);
  CHECK(emitters > 0u);
  bool found = false;
  for (const par::CounterRecord& c : run.record.counters)
    if (c.name == "Partition/emitter_bytes") {
      found = true;
      for (double v : c.perPe) CHECK(v == double(emitters));
    }
  CHECK(found);
  const std::vector<par::PeStageRecord>& tracePes = traceStage(run.record).pes;
  CHECK(tracePes[0].broadcastBytesReceived == 0u);  // PE 0 holds what it broadcasts
  for (std::size_t p = 1; p < tracePes.size(); ++p) CHECK(tracePes[p].broadcastBytesReceived > emitters);
}

TEST_CASE("Results: object-space sends each PE's film to the assembler as counted blocks, P = 2 and 3") {
  for (int pes : {2, 3}) {
    CAPTURE(pes);
    // One voxel per PE: each PE's region of the box holds visible, lit surfaces (with 4 per
    // PE, one PE may own only voxels whose hits add nothing to the film at this size).
    rt::ObjectSpacePartition partition(1);
    checkAssembly(partition, pes);
  }
}

TEST_CASE("Results: object partitioning sends each PE's film to the assembler as counted blocks, P = 2 and 3") {
  for (int pes : {2, 3}) {
    CAPTURE(pes);
    rt::ObjectPartition partition;
    checkAssembly(partition, pes);
  }
}

TEST_CASE("Results: with every PE's foreign geometry poisoned the partitioned tracers still give the sequential image") {
  // Each PE shades from a scene copy whose vertices of triangles it does not hold are NaN: a
  // read of another PE's geometry outside a message would put NaN (dropped by the film) or
  // garbage into the image, so equality means no such read happened.
  const scene::Scene s = scene::loadGltf(bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::TraceOptions opt = partitionedOptions(rt::IntegratorKind::Path, 2);
  const image::Image reference = renderSequential(s, cam, kSize, kSize, opt);
  opt.poisonForeignGeometry = true;
  for (int pes : {2, 3}) {
    CAPTURE(pes);
    rt::ObjectSpacePartition space;
    CHECK(renderPartitioned(space, s, cam, kSize, kSize, opt, pes).image.pixels == reference.pixels);
    rt::ObjectPartition objects;
    CHECK(renderPartitioned(objects, s, cam, kSize, kSize, opt, pes).image.pixels == reference.pixels);
  }
}

TEST_CASE("Results: a poisoned view keeps the held triangles and the emitters, and nothing else") {
  const scene::Scene s = scene::loadGltf(bundledScene("cornell.gltf"));
  const rt::LightSampler lights(s);
  std::vector<uint32_t> held;
  for (uint32_t t = 0; t < uint32_t(s.triangles.size()) / 2; ++t) held.push_back(t);
  const std::unique_ptr<scene::Scene> view = scene::poisonedView(s, held, lights.emitters());
  std::vector<char> kept(s.positions.size(), 0);
  for (uint32_t t : held)
    for (uint32_t v : s.triangles[t].v) kept[v] = 1;
  for (uint32_t t : lights.emitters())
    for (uint32_t v : s.triangles[t].v) kept[v] = 1;
  size_t poisoned = 0;
  for (size_t v = 0; v < s.positions.size(); ++v) {
    if (kept[v]) {
      CHECK(view->positions[v] == s.positions[v]);
    } else {
      CHECK(std::isnan(view->positions[v].x));
      ++poisoned;
    }
  }
  CHECK(poisoned > 0u);  // the other half of the box is really gone
}

}  // namespace
}  // namespace pr::test
