// Tests of the object-space tracer (raytrace/partition/object_space.cpp): images bit-identical
// to the sequential tracer for every P (bundled scenes, shared models, k·P voxels, rays along
// voxel boundaries), exact message counts on a hand-checked scene, traffic invariants, the
// geometry each PE holds, and termination under a timeout guard.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <future>

#include "common/parallel/schedulers/scheduler.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/integrators/integrator_scenes.h"
#include "raytrace/partition/partitioned_test_support.h"

using namespace pr;

namespace {

constexpr int kW = 24, kH = 18;
const int kPes[] = {1, 2, 3, 4, 8};

void checkScene(const std::filesystem::path& file, rt::IntegratorKind kind, int spp, std::initializer_list<int> pes,
                int voxelsPerPe = 1) {
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
    rt::ObjectSpacePartition partition(voxelsPerPe);
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kH, opt, p);
    CHECK(run.image.pixels == reference.pixels);
    test::checkTraffic(run, p);
    CHECK(run.figures.partitions == voxelsPerPe * p);
  }
}

}  // namespace

TEST_CASE("ObjectSpace: Cornell box, Whitted and path tracer, = sequential for P in {1,2,3,4,8}") {
  const rt::IntegratorKind kinds[] = {rt::IntegratorKind::Whitted, rt::IntegratorKind::Path};
  for (rt::IntegratorKind kind : kinds)
    checkScene(test::bundledScene("cornell.gltf"), kind, kind == rt::IntegratorKind::Path ? 2 : 1,
               {kPes[0], kPes[1], kPes[2], kPes[3], kPes[4]});
  checkScene(test::bundledScene("cornell-diffuse.gltf"), rt::IntegratorKind::Path, 1, {1, 2, 3, 4, 8});
}

TEST_CASE("ObjectSpace: hot-spot scene = sequential for P = 3") {
  checkScene(test::bundledScene("hotspot.gltf"), rt::IntegratorKind::Whitted, 1, {3});
}

TEST_CASE("ObjectSpace: hot-spot scene = sequential for P = 8") {
  checkScene(test::bundledScene("hotspot.gltf"), rt::IntegratorKind::Whitted, 1, {8});
}

TEST_CASE("ObjectSpace: k·P voxels = sequential") {
  checkScene(test::bundledScene("cornell.gltf"), rt::IntegratorKind::Path, 1, {2, 3}, 4);
  checkScene(test::bundledScene("hotspot.gltf"), rt::IntegratorKind::Path, 1, {2, 3}, 2);  // the default k
}

TEST_CASE("ObjectSpace: every schedule at P = 3 and 4 = sequential") {
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
      rt::ObjectSpacePartition partition;
      const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kH, opt, p, std::string(info.name));
      CHECK(run.image.pixels == reference.pixels);
      test::checkTraffic(run, p);
    }
}

TEST_CASE("ObjectSpace: scene scales 1e-4 and 1e5 = sequential") {
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
      rt::ObjectSpacePartition partition;
      const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kH, opt, p);
      CHECK(run.image.pixels == reference.pixels);
    }
  }
}

TEST_CASE("ObjectSpace: shared glTF models = sequential") {
  if (!test::haveSharedScenes()) return;
  for (const char* file : {"BoxTextured/glTF/BoxTextured.gltf", "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
                           "Duck/glTF-Binary/Duck.glb"})
    checkScene(test::sharedScenes() / file, rt::IntegratorKind::Path, 1, {2, 4});
}

TEST_CASE("ObjectSpace: axis-aligned city, rays parallel to the split planes, = sequential") {
  // Adjacent boxes on a grid share faces at integer coordinates, where the kd split puts its
  // planes; the top-down orthographic camera's rays run parallel to the vertical planes and
  // cross the horizontal ones where box tops lie. A point light adds shadow rays.
  scene::Scene s = test::emptyScene();
  const uint32_t white = test::addMaterial(s, test::diffuse(0.8f));
  test::addGround(s, 0.0f, white);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const scene::Scene box = test::closedBox(glm::vec3(i - 2, 0, j - 2), glm::vec3(i - 1, 1 + (i * 3 + j) % 4, j - 1), 1);
      test::appendTriangles(s, box, white);
    }
  s.normals.clear();  // the boxes come without: geometric normals everywhere
  s.uvs.clear();
  for (const glm::vec3& p : s.positions) s.bounds.extend(p);
  scene::PunctualLight light;
  light.type = scene::LightType::Point;
  light.position = glm::vec3(0.5f, 8.0f, 0.5f);
  light.color = glm::vec3(1.0f);
  light.intensity = 50.0f;
  s.lights.push_back(light);
  const scene::Camera cam = test::topDownOrtho(10.0f, 2.5f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 2);
  const image::Image reference = test::renderSequential(s, cam, kW, kW, opt);
  CHECK(std::any_of(reference.pixels.begin(), reference.pixels.end(),
                    [](const glm::vec3& c) { return c.x + c.y + c.z > 0.0f; }));
  for (int p : {2, 3, 4, 8}) {
    CAPTURE(p);
    rt::ObjectSpacePartition partition;
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, kW, kW, opt, p);
    CHECK(run.image.pixels == reference.pixels);
    test::checkTraffic(run, p);
  }
}

TEST_CASE("ObjectSpace: two walls, one tile: exactly one ray message") {
  // Walls x = -3 and x = +3; the eye at the origin lies on the split plane x = 0 between
  // them. Pixel 0's ray goes left and stays in voxel 0, pixel 1's goes right and stays in
  // voxel 1 (one voxel per PE: voxel i is PE i's). One tile makes both rays on one PE: the ray
  // of the other PE's voxel is sent once, traced there, and (diffuse, no lights, Whitted)
  // spawns nothing. P = 1: no message.
  const scene::Scene s = test::twoWalls();
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  for (int p : {1, 2}) {
    CAPTURE(p);
    rt::ObjectSpacePartition partition(1);
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 2, 1, opt, p);
    test::checkTraffic(run, p);
    CHECK(run.result.rays.total() == 2);
    CHECK(run.figures.raysSent == (p == 1 ? 0u : 1u));
    uint64_t bytes = 0;
    for (const par::PeStageRecord& pe : test::traceStage(run.record).pes) bytes += pe.bytesSent;
    // One batch of one TravellingRay, counted as its encoding: RayMessage (56), where the walk
    // resumes (t and voxel, 8) and a shadow ray's owners visited (8); the batch's length and
    // sender travel in the message's envelope.
    CHECK(bytes == (p == 1 ? 0u : 72u));
    CHECK(run.figures.triangles == std::vector<uint64_t>(p == 1 ? std::vector<uint64_t>{4} : std::vector<uint64_t>{2, 2}));
  }
}

TEST_CASE("ObjectSpace: a shadow ray is not sent to an owner whose voxel holds only an emitter on its way") {
  // The two walls of the test above, and a two-sided area light at x = -2.5 in voxel 0, out of
  // the two pixels' view. Pixel 1's ray hits the right wall (PE 1's voxel); its shadow ray to
  // the light crosses into voxel 0 but reaches none of the left wall there, only the light,
  // which every PE holds a copy of: PE 1 tests it whole and sends it nowhere. So the one
  // message is still the camera ray sent to the other PE; the image is the sequential one.
  scene::Scene s = test::twoWalls();
  scene::Material lamp;
  lamp.emissiveFactor = glm::vec3(4.0f);
  const uint32_t light = test::addMaterial(s, lamp);
  const glm::vec3 a(-2.5f, 4.0f, -6.0f), b(-2.5f, 6.0f, -6.0f), c(-2.5f, 5.0f, -4.0f);
  scene::Object obj;
  obj.firstTriangle = uint32_t(s.triangles.size());
  obj.triangleCount = 2;
  test::addTriangle(s, a, b, c, light);
  test::addTriangle(s, a, c, b, light);
  s.objects.push_back(obj);
  test::addAreaLights(s, light);
  const scene::Camera cam = test::perspectiveAt(glm::vec3(0.0f), 1.2f);
  const rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Whitted, 1);
  const image::Image reference = test::renderSequential(s, cam, 2, 1, opt);
  CHECK(reference.pixels[1].x > 0.0f);  // the right wall sees the light: its shadow ray was traced, unoccluded
  for (int p : {1, 2}) {
    CAPTURE(p);
    rt::ObjectSpacePartition partition(1);
    const test::PartitionedRun run = test::renderPartitioned(partition, s, cam, 2, 1, opt, p);
    test::checkTraffic(run, p);
    CHECK(run.image.pixels == reference.pixels);
    CHECK(run.result.rays.shadowRays >= 1);
    CHECK(run.figures.raysSent == (p == 1 ? 0u : 1u));
  }
}

TEST_CASE("ObjectSpace: each PE holds only its voxels' geometry") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::ObjectSpacePartition partition(4);  // 16 voxels
  const test::PartitionedRun run =
      test::renderPartitioned(partition, s, cam, 8, 8, test::partitionedOptions(rt::IntegratorKind::Whitted, 1), 4);
  uint64_t triangles = 0;
  for (int p = 0; p < 4; ++p) {
    CHECK(run.figures.triangles[p] > 0);
    // Not the world: the cluster of spheres, most of the triangles but little of the view's
    // work, is cut in two and the rest of the voxels hold parts of the walls (with fewer
    // voxels the cluster may be one voxel, whose owner then holds nearly every triangle).
    CHECK(run.figures.triangles[p] < s.triangles.size() * 7 / 10);
    CHECK(run.figures.geometryBytes[p] > run.figures.triangles[p] * rt::kTriangleVertexBytes);
    triangles += run.figures.triangles[p];
  }
  CHECK(triangles >= s.triangles.size());
  CHECK(triangles < s.triangles.size() * 11 / 10);  // few straddlers
  test::checkTraffic(run, 4);
  CHECK(run.figures.raysSent > 0);
}

TEST_CASE("ObjectSpace: each owner builds its BVH as the trace stage's set-up") {
  const scene::Scene s = scene::loadGltf(test::bundledScene("hotspot.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::ObjectSpacePartition partition;
  const test::PartitionedRun run =
      test::renderPartitioned(partition, s, cam, 16, 16, test::partitionedOptions(rt::IntegratorKind::Path, 1), 3);
  CHECK(std::none_of(run.record.stages.begin(), run.record.stages.end(),
                     [](const par::StageRecord& st) { return st.name == "build"; }));
  const int trace = int(&test::traceStage(run.record) - run.record.stages.data());
  // Per PE: one set-up span in the trace stage, where it built its BVH over what it holds.
  for (int p = 0; p < 3; ++p) {
    CAPTURE(p);
    int setups = 0;
    for (const par::TaskSpan& span : run.record.timeline) setups += span.pe == p && span.stage == trace && span.task == par::kSetupSpan;
    CHECK(setups == 1);
    CHECK(run.figures.triangles[p] > 0);
  }
}

TEST_CASE("ObjectSpace: renders terminate (timeout guard)") {
  // Deep glass and mirror paths at P = 8 with spp 2: if termination detection failed, the
  // stage would never end; the guard turns a hang into a failure.
  const scene::Scene s = scene::loadGltf(test::bundledScene("cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(s, "", 1.0f);
  rt::TraceOptions opt = test::partitionedOptions(rt::IntegratorKind::Path, 2, 16);
  auto done = std::async(std::launch::async, [&] {
    rt::ObjectSpacePartition partition;
    return test::renderPartitioned(partition, s, cam, 12, 12, opt, 8).result.rays.total();
  });
  if (done.wait_for(std::chrono::seconds(60)) != std::future_status::ready) {
    FAIL_CHECK("object-space render did not terminate within 60 s");
    std::quick_exit(1);
  }
  CHECK(done.get() >= 12u * 12u * 2u);
}
