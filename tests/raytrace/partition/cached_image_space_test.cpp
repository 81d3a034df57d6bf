// The image-space tracer with a data manager (raytrace/partition/cached_image_space.h): the
// image and ray counts are the sequential tracer's for every P and every cache size (none,
// 1 KiB, half the largest item, the largest item alone, everything), no PE reads geometry
// it neither owns nor fetched (poisoned views), and the cache figures in the run record agree
// with the messages the DataManager counted.
#include <doctest/doctest.h>

#include <algorithm>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/partition/cached_image_space.h"
#include "raytrace/partition/partitioned_test_support.h"

using namespace pr;

namespace {

double counterMax(const par::RunRecord& record, const char* name) {
  double m = 0.0;
  for (const par::CounterRecord& c : record.counters)
    if (c.name == name)
      for (double v : c.perPe) m = std::max(m, v);
  return m;
}

double counterTotal(const par::RunRecord& record, const char* name) {
  double sum = 0.0;
  for (const par::CounterRecord& c : record.counters)
    if (c.name == name)
      for (double v : c.perPe) sum += v;
  return sum;
}

// Messages on the channel named `name`: the data manager's "geometry items" (replies) and
// "geometry requests", and the owners' shares of the scene, "scene geometry".
uint64_t channelMessages(const par::RunRecord& record, const char* name) {
  uint64_t n = 0;
  for (const par::StageRecord& st : record.stages)
    for (const par::ChannelTraffic& c : st.channels)
      if (c.name == name) n += c.messages;
  return n;
}

}  // namespace

TEST_CASE("CachedImageSpace: the sequential image for P = 1, 2, 3 and every cache size") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  for (const rt::IntegratorKind kind : {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path}) {
    rt::TraceOptions opt = test::partitionedOptions(kind, 1, 4);
    par::Runtime one(1, "demand");
    const rt::TraceResult sequential = rt::renderRays(s, cam, 24, 24, opt, "sequential", one);
    const image::Image& reference = sequential.image;
    for (int pes : {1, 2, 3}) {
      CAPTURE(pes);
      rt::CachedImageSpacePartition partition;
      const test::PartitionedRun all = test::renderPartitioned(partition, s, cam, 24, 24, opt, pes);
      CHECK(all.image.pixels == reference.pixels);
      CHECK(all.result.rays.cameraRays == sequential.rays.cameraRays);
      CHECK(all.result.rays.continuationRays == sequential.rays.continuationRays);
      CHECK(all.result.rays.shadowRays == sequential.rays.shadowRays);
      const auto largest = std::size_t(counterMax(all.record, "Cache/largest_item_bytes"));
      CHECK(largest > 0u);
      if (pes > 1) {
        // A cache that holds everything fetches each remote item at most once per PE.
        CHECK(counterTotal(all.record, "Cache/misses") <= double(pes) * all.figures.partitions);
        CHECK(counterTotal(all.record, "Cache/hits") > 0.0);
      }
      for (const std::size_t bytes : {std::size_t{0}, std::size_t{1024}, largest / 2, largest}) {
        CAPTURE(bytes);
        opt.cacheBytes = bytes;
        const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 24, 24, opt, pes);
        CHECK(run.image.pixels == reference.pixels);
        CHECK(counterMax(run.record, "Cache/bytes_held_at_end") <= double(bytes));
        if (bytes == 0) CHECK(counterTotal(run.record, "Cache/hits") == 0.0);  // no cache: every use fetches
        if (pes == 1) CHECK(channelMessages(run.record, "geometry items") == 0u);
        // PE 0 sent every other PE its share of the scene, one message each.
        CHECK(channelMessages(run.record, "scene geometry") == uint64_t(pes - 1));
        // Every miss and every prefetch is one request and one reply.
        const double fetches = counterTotal(run.record, "Cache/misses") + counterTotal(run.record, "Cache/prefetches");
        CHECK(double(channelMessages(run.record, "geometry items")) == fetches);
        CHECK(double(channelMessages(run.record, "geometry requests")) == fetches);
      }
      opt.cacheBytes = rt::kDefaultCacheBytes;
    }
  }
}

TEST_CASE("CachedImageSpace: with every PE's foreign geometry poisoned the image is still the sequential one") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 2);
  const image::Image reference = test::renderSequential(s, cam, 32, 32, opt);
  opt.poisonForeignGeometry = true;
  for (int pes : {2, 3}) {
    CAPTURE(pes);
    for (const std::size_t bytes : {std::size_t{0}, rt::kDefaultCacheBytes}) {
      opt.cacheBytes = bytes;
      rt::CachedImageSpacePartition partition;
      CHECK(test::renderPartitioned(partition, s, cam, 32, 32, opt, pes).image.pixels == reference.pixels);
    }
  }
}

TEST_CASE("CachedImageSpace: each PE holds only its own items, P = 1 moves nothing") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  for (int pes : {1, 2, 4}) {
    CAPTURE(pes);
    rt::CachedImageSpacePartition partition;
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 16, 16, opt, pes);
    uint64_t triangles = 0;
    for (int p = 0; p < pes; ++p) {
      CHECK(run.figures.triangles[size_t(p)] > 0u);
      triangles += run.figures.triangles[size_t(p)];
    }
    CHECK(triangles == s.triangles.size());  // every triangle in exactly one item
    if (pes == 1) CHECK(channelMessages(run.record, "geometry items") == 0u);
  }
}

TEST_CASE("CachedImageSpace: latency hiding and a simulated latency keep the sequential image and counts") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 1, 4);
  par::Runtime one(1, "demand");
  const rt::TraceResult sequential = rt::renderRays(s, cam, 16, 16, opt, "sequential", one);
  rt::CachedImageSpacePartition partition;
  const std::size_t largest =
      std::size_t(counterMax(test::renderPartitioned(partition, s, cam, 16, 16, opt, 2).record, "Cache/largest_item_bytes"));
  for (const bool hide : {false, true})
    for (const double latency : {0.0, 20e-6})
      for (const std::size_t bytes : {std::size_t{0}, largest, rt::kDefaultCacheBytes})
        for (int pes : {2, 3}) {
          CAPTURE(hide);
          CAPTURE(latency);
          CAPTURE(bytes);
          CAPTURE(pes);
          opt.hideLatency = hide;
          opt.dataLatencySeconds = latency;
          opt.cacheBytes = bytes;
          const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 16, 16, opt, pes);
          CHECK(run.image.pixels == sequential.image.pixels);
          CHECK(run.result.rays.total() == sequential.rays.total());
          const double fetches = counterTotal(run.record, "Cache/misses") + counterTotal(run.record, "Cache/prefetches");
          CHECK(double(channelMessages(run.record, "geometry items")) == fetches);
          CHECK(counterMax(run.record, "Cache/bytes_held_at_end") <= double(bytes));
        }
}

TEST_CASE("CachedImageSpace: profiling predicts a tile's items from its neighbours and gives the cost schedules estimates") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 1, 4);
  opt.tileSizePx = 8;  // 16 tiles of 32 x 32: most have finished neighbours on their PE
  par::Runtime one(1, "demand");
  const rt::TraceResult sequential = rt::renderRays(s, cam, 32, 32, opt, "sequential", one);
  rt::CachedImageSpacePartition partition;
  const std::size_t largest =
      std::size_t(counterMax(test::renderPartitioned(partition, s, cam, 32, 32, opt, 2).record, "Cache/largest_item_bytes"));
  opt.cacheBytes = 4 * largest;  // a profile prediction may take two items
  using Prefetch = rt::TraceOptions::Prefetch;
  for (const Prefetch mode : {Prefetch::None, Prefetch::CameraRays, Prefetch::Profile}) {
    CAPTURE(int(mode));
    opt.prefetch = mode;
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 32, 32, opt, 2);
    CHECK(run.image.pixels == sequential.image.pixels);
    CHECK(run.result.rays.total() == sequential.rays.total());
    const double prefetches = counterTotal(run.record, "Cache/prefetches");
    const double fromProfile = counterTotal(run.record, "Cache/prefetches_from_profile");
    const double used = counterTotal(run.record, "Cache/prefetches_used");
    CHECK(double(channelMessages(run.record, "geometry items")) == counterTotal(run.record, "Cache/misses") + prefetches);
    CHECK(used <= prefetches);
    if (mode == Prefetch::None) CHECK(prefetches == 0.0);
    if (mode == Prefetch::CameraRays) CHECK(fromProfile == 0.0);
    if (mode == Prefetch::Profile) {
      CHECK(fromProfile > 0.0);
      CHECK(used > 0.0);  // the neighbours' items were the tile's too
    }
    for (const par::StageRecord& st : run.record.stages) CHECK(st.name.find("profile pre-pass") == std::string::npos);
  }
  // The cost schedules get a profile pre-pass; its rays are not the render's.
  opt.prefetch = Prefetch::Profile;
  for (const char* schedule : {"unbalanced", "hot-spots"}) {
    CAPTURE(schedule);
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 32, 32, opt, 2, schedule);
    CHECK(run.image.pixels == sequential.image.pixels);
    CHECK(run.result.rays.cameraRays == sequential.rays.cameraRays);
    CHECK(run.result.rays.total() == sequential.rays.total());
    const auto prePass = std::find_if(run.record.stages.begin(), run.record.stages.end(), [](const par::StageRecord& st) {
      return st.name.find("profile pre-pass") != std::string::npos;
    });
    REQUIRE(prePass != run.record.stages.end());
    CHECK(prePass->tasks.size() == 16u);
    // The trace stage's tasks carry the profile's costs (rays per tile), not pixel counts.
    const auto trace = std::find_if(run.record.stages.begin(), run.record.stages.end(),
                                    [](const par::StageRecord& st) { return st.name == "trace"; });
    REQUIRE(trace != run.record.stages.end());
    REQUIRE(trace->tasks.size() == 16u);
    const auto [low, high] = std::minmax_element(trace->tasks.begin(), trace->tasks.end(),
                                                 [](const auto& a, const auto& b) { return a.costEstimate < b.costEstimate; });
    CHECK(high->costEstimate > low->costEstimate);
    CHECK(low->costEstimate >= 64.0);  // at least one ray per pixel of an 8 x 8 tile
  }
}
