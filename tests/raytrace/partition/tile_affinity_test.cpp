// Tests of tile affinity (raytrace/partition/tile_affinity.cpp): the vote of a tile's probes
// for the owner each hits first, and the preferred PEs the partitioned tracers give their
// camera-ray tiles (the owner of what the tile sees), carried in the run record.
#include <doctest/doctest.h>

#include "raytrace/core/geometry_builders.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/object_partition.h"
#include "raytrace/partition/object_space.h"
#include "raytrace/partition/partition_margin.h"
#include "raytrace/partition/partitioned_test_support.h"
#include "raytrace/partition/tile_affinity.h"

using namespace pr;

namespace {

constexpr float kInf = rt::kInfinity;

}  // namespace

TEST_CASE("TileAffinity: a tile prefers the PE whose geometry most of its probes hit first") {
  static_assert(rt::kAffinityProbesPerTile == 4);
  // Tile 0: PE 0 nearer for three probes. Tile 1: two each, the tie to the lower PE. Tile 2:
  // the shared geometry is nearer for every probe. Tile 3: nothing hit.
  const std::vector<std::vector<float>> nearest = {
      {1, 1, 1, 5, 1, 1, 5, 5, 3, 3, 3, 3, kInf, kInf, kInf, kInf},
      {2, 2, 2, 2, 2, 2, 1, 1, 4, 4, 4, 4, kInf, kInf, kInf, kInf}};
  const std::vector<float> shared = {9, 9, 9, 9, 9, 9, 9, 9, 1, 1, 1, 1, kInf, kInf, kInf, kInf};
  CHECK(rt::preferredPes(rt::nearestOwners(nearest, shared), 4, 2) == std::vector<int>{0, 0, -1, -1});
  // Without shared geometry tile 2's probes hit PE 0 first.
  CHECK(rt::preferredPes(rt::nearestOwners(nearest, {}), 4, 2) == std::vector<int>{0, 0, 0, -1});
}

TEST_CASE("TileAffinity: probes are camera rays through each tile's quarters") {
  const scene::Scene s = test::twoWalls();
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  const rt::TraceJob job{s, cam, 32, 16, opt};
  const std::shared_ptr<const rt::Integrator> integrator = rt::jobIntegrator(job);
  const std::vector<rt::PixelRect> tiles = {{0, 0, 16, 16}, {16, 0, 32, 16}, {5, 5, 6, 6}};
  const std::vector<rt::Ray> probes = rt::affinityProbes(*integrator, tiles);
  REQUIRE(probes.size() == 12);
  for (int i = 0; i < 4; ++i) {
    CHECK(probes[size_t(i)].direction.x < 0.0f);      // left tile: towards the left wall
    CHECK(probes[size_t(4 + i)].direction.x > 0.0f);  // right tile
    CHECK(probes[size_t(8 + i)].direction == probes[8].direction);  // a one-pixel tile: one pixel
  }
}

TEST_CASE("TileAffinity: the partitioned tracers' tiles prefer the owner of the wall they show") {
  const scene::Scene s = test::twoWalls();
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  opt.tileSizePx = 16;
  const image::Image reference = test::renderSequential(s, cam, 32, 16, opt);
  rt::ObjectPartition object;
  rt::ObjectSpacePartition objectSpace(1);
  for (rt::Partition* tracer : std::initializer_list<rt::Partition*>{&object, &objectSpace}) {
    const bool isObject = tracer == &object;
    CAPTURE(isObject);
    const test::PartitionedRun run = test::renderPartitioned(*tracer, s, cam, 32, 16, opt, 2, "preferred-bias");
    CHECK(run.image.pixels == reference.pixels);
    const par::StageRecord& trace = test::traceStage(run.record);
    REQUIRE(trace.tasks.size() == 2);
    // The left tile shows the left wall (triangles 0 and 1): its owner is the object
    // assignment's (object partitioning) or voxel 0's, PE 0, below the split plane x = 0
    // (object-space, one voxel per PE).
    int leftOwner = 0;
    if (isObject) {
      const rt::ObjectAssignment assignment(s, {2, 0, rt::partitionMargin(s, cam.position()), 0.0});
      for (const rt::ObjectPiece& piece : assignment.pieces())
        if (piece.triangles.front() == 0) leftOwner = piece.owner;
    }
    CHECK(trace.tasks[0].preferredPe == leftOwner);
    CHECK(trace.tasks[1].preferredPe == 1 - leftOwner);
    // At P = 1 there is no one else to prefer.
    const test::PartitionedRun one = test::renderPartitioned(*tracer, s, cam, 32, 16, opt, 1, "preferred-bias");
    for (const par::TaskInfo& t : test::traceStage(one.record).tasks) CHECK(t.preferredPe == -1);
  }
}
