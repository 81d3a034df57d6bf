// Rays in batches per destination (common/parallel/batched_channel.h) in the two partitioned
// tracers: the image is the sequential one for every batch size, from one ray per message to
// more than a frame's rays, and larger batches send fewer messages for the same rays.
#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "raytrace/partition/object_partition.h"
#include "raytrace/partition/object_space.h"
#include "raytrace/partition/partitioned_test_support.h"

using namespace pr;

namespace {

uint64_t messagesSent(const test::PartitionedRun& run) {
  uint64_t n = 0;
  for (const par::PeStageRecord& pe : test::traceStage(run.record).pes) n += pe.messagesSent;
  return n;
}

template <class P>
void checkBatchSizes(const scene::Scene& s, const scene::Camera& cam) {
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 1, 4);
  const image::Image reference = test::renderSequential(s, cam, 24, 24, opt);
  for (int pes : {2, 3}) {
    uint64_t one = 0, many = 0;
    for (int batch : {1, 5, 64, rt::kMaxRayBatch}) {
      CAPTURE(pes);
      CAPTURE(batch);
      opt.rayBatch = batch;
      P partition;
      const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 24, 24, opt, pes);
      CHECK(run.image.pixels == reference.pixels);
      test::checkTraffic(run, pes, batch);
      if (batch == 1) one = messagesSent(run);
      if (batch == 64) many = messagesSent(run);
    }
    // How full a batch gets depends on when PEs run dry (timing); a tile's camera rays to one
    // owner always share a batch, so there are fewer messages. bench_partitioned measures it.
    CHECK(one > 0u);
    CHECK(many < one);
  }
}

}  // namespace

TEST_CASE("RayBatches: object-space gives the sequential image for every batch size, fewer messages for larger ones") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  checkBatchSizes<rt::ObjectSpacePartition>(s, scene::selectCamera(s, "", 1.0f));
}

TEST_CASE("RayBatches: object partitioning gives the sequential image for every batch size, fewer messages for larger ones") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  checkBatchSizes<rt::ObjectPartition>(s, scene::selectCamera(s, "", 1.0f));
}

TEST_CASE("RayBatches: a batch size outside [1, kMaxRayBatch] is an input error") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  for (int batch : {0, -3, rt::kMaxRayBatch + 1}) {
    CAPTURE(batch);
    rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
    opt.rayBatch = batch;
    rt::ObjectSpacePartition space;
    CHECK_THROWS_AS(test::renderPartitioned(space, s, cam, 8, 8, opt, 2), InputError);
    rt::ObjectPartition objects;
    CHECK_THROWS_AS(test::renderPartitioned(objects, s, cam, 8, 8, opt, 2), InputError);
  }
}
