// Tests of the object-partitioning tracer (raytrace/partition/object_partition.cpp): images
// bit-identical to the sequential tracer for every P (bundled scenes, shared models, small
// pieces), exact query and hit message counts on a hand-checked scene, traffic invariants,
// geometry held per PE (each triangle on exactly one PE), termination under a timeout guard.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <future>

#include "common/parallel/batched_channel.h"
#include "common/parallel/schedulers/scheduler.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/object_partition.h"
#include "raytrace/partition/partitioned_test_support.h"

using namespace pr;

namespace {

constexpr int kW = 24, kH = 18;

void checkScene(const std::filesystem::path& file, rt::IntegratorKind kind, int spp, std::initializer_list<int> pes,
                uint32_t maxPieceTriangles = 0) {
  scene::Scene s = scene::loadGltf(file);
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  test::addHeadlightIfUnlit(s, cam);
  const rt::TraceOptions opt = test::partitionedOptions(kind, spp);
  const image::Image reference = test::renderSequential(s, cam, kW, kH, opt);
  CHECK(std::any_of(reference.pixels.begin(), reference.pixels.end(),
                    [](const glm::vec3& c) { return c.x + c.y + c.z > 0.0f; }));  // not a black frame
  for (int p : pes) {
    CAPTURE(file);
    CAPTURE(p);
    rt::ObjectPartition partition(maxPieceTriangles);
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kH, opt, p);
    CHECK(run.image.pixels == reference.pixels);
    test::checkTraffic(run, p);
    uint64_t held = 0;
    for (uint64_t n : run.figures.triangles) held += n;
    // Objects are not duplicated, unlike straddling voxels, but for the replicated pieces.
    const rt::ObjectAssignment assignment(s, {p, maxPieceTriangles, 0.0f, rt::kReplicatedFraction});
    CHECK(held == s.triangles.size() + uint64_t(p - 1) * assignment.replicated().size());
  }
}

}  // namespace

TEST_CASE("ObjectPartition: Cornell box, Whitted and path tracer, = sequential for P in {1,2,3,4,8}") {
  checkScene(test::bundledScene("cornell.gltf"), rt::IntegratorKind::Whitted, 1, {1, 2, 3, 4, 8});
  checkScene(test::bundledScene("cornell.gltf"), rt::IntegratorKind::Path, 2, {1, 2, 3, 4, 8});
  checkScene(test::bundledScene("cornell-diffuse.gltf"), rt::IntegratorKind::Path, 1, {1, 2, 3, 4, 8});
}

TEST_CASE("ObjectPartition: hot-spot scene = sequential for P = 3") {
  checkScene(test::bundledScene("hotspot.gltf"), rt::IntegratorKind::Whitted, 1, {3});
}

TEST_CASE("ObjectPartition: hot-spot scene = sequential for P = 8") {
  checkScene(test::bundledScene("hotspot.gltf"), rt::IntegratorKind::Whitted, 1, {8});
}

TEST_CASE("ObjectPartition: pieces of two triangles = sequential") {
  checkScene(test::bundledScene("cornell.gltf"), rt::IntegratorKind::Path, 1, {2, 3}, 2);
}

TEST_CASE("ObjectPartition: every schedule at P = 3 and 4 = sequential") {
  // Schedules decide which PE makes which tile's camera rays; the rays' paths through the
  // owners, and so the image, must not depend on it.
  const scene::Scene s = scene::loadGltf(test::bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 1);
  const image::Image reference = test::renderSequential(s, cam, kW, kH, opt);
  for (const par::ScheduleInfo& info : par::schedules())
    for (int p : {3, 4}) {
      CAPTURE(info.name);
      CAPTURE(p);
      rt::ObjectPartition partition;
      const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kH, opt, p, std::string(info.name));
      CHECK(run.image.pixels == reference.pixels);
      test::checkTraffic(run, p);
    }
}

TEST_CASE("ObjectPartition: scene scales 1e-4 and 1e5 = sequential") {
  // The margins grow with the scene's coordinates (partition_margin.h): at every scale the
  // partitioned hits must be the full BVH's.
  for (float k : {1e-4f, 1e5f}) {
    scene::Scene s = scene::loadGltf(test::bundledScene("cornell.gltf"));
    test::scaleScene(s, k);
    const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
    const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 1);
    const image::Image reference = test::renderSequential(s, cam, kW, kH, opt);
    CHECK(std::any_of(reference.pixels.begin(), reference.pixels.end(),
                      [](const glm::vec3& c) { return c.x + c.y + c.z > 0.0f; }));
    for (int p : {3, 8}) {
      CAPTURE(k);
      CAPTURE(p);
      rt::ObjectPartition partition;
      const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kH, opt, p);
      CHECK(run.image.pixels == reference.pixels);
    }
  }
}

TEST_CASE("ObjectPartition: shared glTF models = sequential") {
  if (!test::haveSharedScenes()) return;
  for (const char* file : {"BoxTextured/glTF/BoxTextured.gltf", "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
                           "Duck/glTF-Binary/Duck.glb"})
    checkScene(test::sharedScenes() / file, rt::IntegratorKind::Path, 1, {2, 4});
}

TEST_CASE("ObjectPartition: two walls, one tile: exactly one query and one hit message") {
  // Walls x = -3 (object 0) and x = +3 (object 1), two triangles each: LPT gives object 0 to
  // PE 0 and object 1 to PE 1. From the eye at the origin, pixel 0's ray can reach only the
  // left wall's bounds and pixel 1's only the right's. One tile makes both rays on one PE: it
  // answers its own wall's ray itself and sends one query for the other, which returns one
  // hit record. Diffuse, no lights, Whitted: nothing is spawned. P = 1: no message.
  const scene::Scene s = test::twoWalls();
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  const image::Image reference = test::renderSequential(s, cam, 2, 1, opt);
  for (int p : {1, 2}) {
    CAPTURE(p);
    rt::ObjectPartition partition;
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 2, 1, opt, p);
    test::checkTraffic(run, p);
    CHECK(run.image.pixels == reference.pixels);
    CHECK(run.result.rays.total() == 2);
    CHECK(run.figures.raysSent == (p == 1 ? 0u : 1u));
    CHECK(run.figures.hitsSent == (p == 1 ? 0u : 1u));
    if (p == 2) {
      const par::StageRecord& st = test::traceStage(run.record);
      REQUIRE(st.traffic.size() == 2);  // the query one way, the hit the other
      CHECK(st.traffic[0].messages == 1);
      CHECK(st.traffic[1].messages == 1);
      // The query carries a ray (32 bytes) and its return address (a batch of one, counted as
      // its one query's encoding); the hit reply an 8-byte header, the hit record and the
      // surface interaction, so it is the larger.
      // Which PE originates depends on which PE took the tile, so tell them apart by size.
      CHECK(st.traffic[0].from == st.traffic[1].to);
      const bool firstIsQuery = st.traffic[0].bytes < st.traffic[1].bytes;
      const auto& query = firstIsQuery ? st.traffic[0] : st.traffic[1];
      const auto& hit = firstIsQuery ? st.traffic[1] : st.traffic[0];
      CHECK(query.bytes >= sizeof(rt::Ray));
      CHECK(query.bytes <= sizeof(rt::Ray) + 8);
      CHECK(hit.bytes == 8 + sizeof(rt::Hit) + sizeof(rt::SurfaceInteraction));
    }
  }
}

TEST_CASE("ObjectPartition: replicated walls are answered on the originator, without a query") {
  // The two walls of the test above, both replicated (a budget of every triangle): each PE
  // holds both, and the ray that reached the other PE's wall is answered where it started.
  const scene::Scene s = test::twoWalls();
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  const image::Image reference = test::renderSequential(s, cam, 2, 1, opt);
  rt::ObjectPartition partition(0, 1.0);
  const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 2, 1, opt, 2);
  test::checkTraffic(run, 2);
  CHECK(run.image.pixels == reference.pixels);
  CHECK(run.result.rays.total() == 2);
  CHECK(run.figures.raysSent == 0u);
  CHECK(run.figures.hitsSent == 0u);
  CHECK(run.figures.triangles == std::vector<uint64_t>{4, 4});
}

TEST_CASE("ObjectPartition: PEs hold balanced geometry, disjoint but for the replicated pieces") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::ObjectPartition partition;
  const test::PartitionedRun run =
      test::renderPartitioned(partition, s, cam, 8, 8, test::partitionedOptions(rt::IntegratorKind::Whitted, 1), 4);
  uint64_t triangles = 0, lo = s.triangles.size(), hi = 0;
  for (int p = 0; p < 4; ++p) {
    CHECK(run.figures.geometryBytes[p] > run.figures.triangles[p] * rt::kTriangleVertexBytes);
    triangles += run.figures.triangles[p];
    lo = std::min(lo, run.figures.triangles[p]);
    hi = std::max(hi, run.figures.triangles[p]);
  }
  const rt::ObjectAssignment assignment(s, {4, 0, 0.0f, rt::kReplicatedFraction});
  CHECK(!assignment.replicated().empty());  // the floor and the back wall
  CHECK(triangles == s.triangles.size() + 3 * assignment.replicated().size());
  CHECK(double(hi) <= 1.1 * double(lo));  // LPT over pieces of at most 1/16 of the scene
  test::checkTraffic(run, 4);
  CHECK(run.figures.raysSent > 0);
  CHECK(run.figures.hitsSent == run.figures.raysSent);  // every remote query is answered
}

TEST_CASE("ObjectPartition: renders terminate (timeout guard)") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 2, 16);
  auto done = std::async(std::launch::async, [&] {
    rt::ObjectPartition partition;
    return test::renderPartitioned(partition, s, cam, 12, 12, opt, 8).result.rays.total();
  });
  if (done.wait_for(std::chrono::seconds(60)) != std::future_status::ready) {
    FAIL_CHECK("object-partitioning render did not terminate within 60 s");
    std::quick_exit(1);
  }
  CHECK(done.get() >= 12u * 12u * 2u);
}
