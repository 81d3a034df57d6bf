// SceneDistribution: the raster methods record how the scene reaches the PEs, in the first
// frame only. Sort-middle and sort-last replicate it (one broadcast of the whole scene per PE);
// sort-first broadcasts the shading data and sends each PE its share of primitives as counted
// data messages; sort-first's primitive messages count the primitives' data, so its primitive
// traffic and sort-middle's screen triangles are both measured in bytes and comparable.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>

#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"
#include "common/scene/poisoned_view.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/log.h"
#include "raster/parallel_pipeline.h"
#include "raster/scene_distribution.h"
#include "raster/sort/sort_test_support.h"
#include "test_support.h"

namespace pr::raster {
namespace {

uint64_t broadcastBytes(const par::RunRecord& record, size_t firstStage, size_t endStage, int pe) {
  uint64_t bytes = 0;
  for (size_t i = firstStage; i < endStage; ++i) bytes += record.stages[i].pes[size_t(pe)].broadcastBytesReceived;
  return bytes;
}

scene::Scene cornell() {
  setQuiet(true);
  return scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
}

TEST_CASE("SceneDistribution: sort-middle and sort-last replicate the whole scene, once, in the first frame") {
  const scene::Scene s = cornell();
  const FrameView view = makeFrameView(scene::selectCamera(s, "", 4.0f / 3.0f), 32, 24);
  CHECK(geometryBytes(s) + shadingDataBytes(s) == s.memoryBytes());
  for (const char* method : {"sort-middle", "sort-last"}) {
    CAPTURE(method);
    par::Runtime rt(2, "demand");
    std::unique_ptr<SortPoint> sortPoint = makeSortPoint(method);
    renderFrame(*sortPoint, s, view, SortOptions{}, rt);
    const size_t firstFrameStages = rt.record().stages.size();
    renderFrame(*sortPoint, s, view, SortOptions{}, rt);
    for (int p = 0; p < 2; ++p) {
      CAPTURE(p);
      CHECK(broadcastBytes(rt.record(), 0, firstFrameStages, p) == (p == 0 ? 0 : s.memoryBytes()));  // PE 0 holds it
      CHECK(broadcastBytes(rt.record(), firstFrameStages, rt.record().stages.size(), p) == 0);
      CHECK(test::counterTotal(rt.record(), "Scene/geometry_bytes_held", p) == double(geometryBytes(s)));
      CHECK(test::counterTotal(rt.record(), "Scene/primitives_held", p) == double(s.triangles.size()));
    }
  }
}

TEST_CASE("SceneDistribution: sort-first sends each PE its share and broadcasts the shading data") {
  // Three triangles on three PEs: one each; PE 0 keeps triangle 0 and sends PEs 1 and 2 one
  // message of one primitive each (kPrimitiveBytes) in the distribute stage.
  const scene::Scene s = test::threeTriangles();
  par::Runtime rt(3, "balanced");
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  renderParallel(s, test::tinyView(), "sort-first", options, rt);
  const test::StageTraffic distribute = test::stageTraffic(rt.record(), "sort-first distribute");
  CHECK(distribute.messagesSent == 2);
  CHECK(distribute.bytesSent == 2 * kPrimitiveBytes);
  CHECK(test::stageTraffic(rt.record(), "sort-first distribute", 0).messagesSent == 2);
  CHECK(test::channelTraffic(rt.record(), "data").bytes == 2 * kPrimitiveBytes);
  REQUIRE(rt.record().stages[0].name == "sort-first distribute");
  for (int p = 0; p < 3; ++p) {
    CAPTURE(p);
    CHECK(rt.record().stages[0].pes[size_t(p)].broadcastBytesReceived == (p == 0 ? 0 : shadingDataBytes(s)));
    CHECK(test::counterTotal(rt.record(), "Scene/primitives_held", p) == 1);
    CHECK(test::counterTotal(rt.record(), "Scene/geometry_bytes_held", p) == double(kPrimitiveBytes));
  }
}

// A primitive's record carries everything the stages read of it: decoded on another rank and
// installed into a copy of the scene in which every vertex is NaN, the triangle's vertices are
// the scene's again. Bad bytes are refused.
TEST_CASE("SceneDistribution: a primitive message that left its rank, installed into a poisoned copy, restores that primitive's vertices") {
  scene::Scene s = cornell();
  for (size_t v = 0; v < s.positions.size(); ++v) {  // every attribute present, each vertex its own
    s.colors.push_back(glm::vec4(float(v), 0.5f, 0.25f, 1.0f));
    s.tangents.push_back(glm::vec4(1.0f, 0.0f, float(v), -1.0f));
  }
  const uint32_t id = uint32_t(s.triangles.size() / 2);
  std::unique_ptr<scene::Scene> view = scene::poisonedView(s, {});
  const uint32_t v0 = s.triangles[id].v[0];
  CHECK(std::isnan(view->positions[v0].x));
  // A batch inside a rank names the primitive; what leaves a rank is its record.
  const PrimitiveBatch named{&s, {id}, {}};
  CHECK(par::wireSize(named) == kPrimitiveBytes);
  const PrimitiveBatch arrived = par::decodeMessage<PrimitiveBatch>(par::encodeMessage(named));
  REQUIRE(arrived.size() == 1);
  CHECK(arrived.id(0) == id);
  CHECK(arrived.source == nullptr);
  const PrimitiveRecord r = arrived.records[0];
  installPrimitives(*view, arrived);
  for (uint32_t v : s.triangles[id].v) {
    CHECK(view->positions[v] == s.positions[v]);
    CHECK(view->normals[v] == s.normals[v]);
    CHECK(view->uvs[v] == s.uvs[v]);
    CHECK(view->colors[v] == s.colors[v]);
    CHECK(view->tangents[v] == s.tangents[v]);
  }
  // A record naming a triangle the scene does not have is refused, not written.
  PrimitiveRecord bad = r;
  bad.id = uint32_t(s.triangles.size());
  CHECK_THROWS_AS(installPrimitive(*view, bad), par::WireError);
  PrimitiveRecord badMaterial = r;
  badMaterial.triangle.material = uint32_t(s.materials.size());
  CHECK_THROWS_AS(installPrimitive(*view, badMaterial), par::WireError);
  par::Bytes shortened = par::encodeMessage(named);
  shortened.pop_back();
  CHECK_THROWS_AS(par::decodeMessage<PrimitiveBatch>(shortened), par::WireError);
}

TEST_CASE("SceneDistribution: sort-first and sort-middle primitive traffic are both counted in bytes") {
  // The Cornell box at P = 2 in 16-pixel tiles: both methods move primitives between PEs;
  // sort-first's are counted as their data (kPrimitiveBytes each), sort-middle's as the
  // 80-byte screen triangles.
  const scene::Scene s = cornell();
  const FrameView view = makeFrameView(scene::selectCamera(s, "", 4.0f / 3.0f), 64, 48);
  SortOptions options;
  options.regions = RegionStrategy::StaticTiles;
  options.tileSizePx = 16;
  options.batchSize = 64;
  par::Runtime first(2, "demand"), middle(2, "demand");
  renderParallel(s, view, "sort-first", options, first);
  renderParallel(s, view, "sort-middle", options, middle);
  const test::ChannelSum a = test::channelTraffic(first.record(), "primitives");
  const test::ChannelSum b = test::channelTraffic(middle.record(), "primitives");
  CHECK(a.bytes > 0);
  CHECK(b.bytes > 0);
  CHECK(a.bytes == uint64_t(test::counterTotal(first.record(), "Sort/primitives_sent")) * kPrimitiveBytes);
  CHECK(b.bytes == uint64_t(test::counterTotal(middle.record(), "Sort/triangles_sent")) * sizeof(ScreenTriangle));
  // Sort-first's scene distribution is counted too: PE 1's share, in one data message.
  const auto [lo, hi] = primitiveShare(uint32_t(s.triangles.size()), 1, 2);
  CHECK(test::channelTraffic(first.record(), "data").bytes == uint64_t(hi - lo) * kPrimitiveBytes);
}

}  // namespace
}  // namespace pr::raster
