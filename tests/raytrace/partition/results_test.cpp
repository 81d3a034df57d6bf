// Image assembly in the partitioned tracers: every PE's film contributions travel to the
// assembler (PE 0) as counted film-block messages in an "assemble" stage, the emitters are
// counted in the broadcast, and the image stays the sequential one.
#include <doctest/doctest.h>

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
  for (const par::PeStageRecord& r : traceStage(run.record).pes) CHECK(r.broadcastBytesReceived > emitters);
}

TEST_CASE("Results: object-space sends each PE's film to the assembler as counted blocks, P = 2 and 3") {
  for (int pes : {2, 3}) {
    CAPTURE(pes);
    rt::ObjectSpacePartition partition;
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

}  // namespace
}  // namespace pr::test
