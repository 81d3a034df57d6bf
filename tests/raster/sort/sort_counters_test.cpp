// Sort counters in the run record, the only way figures leave a sort point: every sort point
// puts its per-PE counters (Sort/...) in the runtime's RunRecord, only those that belong to it,
// as totals over the frames of a run, agreeing with what its Channels counted; the render
// command's --metrics JSON holds the same totals its details line prints.
#include <doctest/doctest.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "common/parallel/run_record.h"
#include "common/parallel/runtime.h"
#include "raster/parallel_pipeline.h"
#include "raster/scene_distribution.h"
#include "raster/sort/sort_test_support.h"
#include "test_support.h"

namespace pr::raster {
namespace {

const par::CounterRecord* findCounter(const par::RunRecord& record, const std::string& name) {
  for (const par::CounterRecord& c : record.counters)
    if (c.name == name) return &c;
  return nullptr;
}

size_t sortCounterCount(const par::RunRecord& record) {
  size_t n = 0;
  for (const par::CounterRecord& c : record.counters) n += c.name.rfind("Sort/", 0) == 0;
  return n;
}

double total(const par::CounterRecord& c) {
  double sum = 0.0;
  for (double v : c.perPe) sum += v;
  return sum;
}

// A ring of small triangles around the origin, seen from above at an angle: turning the camera
// moves them across regions, so sort-first migrates primitives from frame to frame.
scene::Scene ring() {
  scene::Scene s = test::emptyScene();
  for (int i = 0; i < 24; ++i) {
    const float a = 6.2831853f * i / 24.0f;
    const glm::vec3 c(3.0f * std::cos(a), 0.0f, 3.0f * std::sin(a));
    test::addTriangle(s, c + glm::vec3(-0.3f, -0.3f, 0), c + glm::vec3(0.3f, -0.3f, 0), c + glm::vec3(0, 0.4f, 0));
  }
  for (auto& m : s.materials) m.doubleSided = true;
  return s;
}

// The channel that carries what a sort point's "sent" counter counts, and the bytes per item.
struct SentChannel {
  std::string counter, channel;
  uint64_t itemBytes;
};
SentChannel sentChannel(const std::string& method, RegionStrategy regions) {
  const bool dynamic = regions == RegionStrategy::Dynamic;
  if (method == "sort-first")
    return {"Sort/primitives_sent", dynamic ? "sort-first tile replies" : "scene primitives", kPrimitiveBytes};
  if (method == "sort-middle")
    return {"Sort/triangles_sent", dynamic ? "sort-middle tile replies" : "screen triangles", sizeof(ScreenTriangle)};
  return {"Sort/composite_bytes", "pixels", 1};
}

TEST_CASE("SortCounters: each sort point's per-PE counters reach the run record as totals over the frames") {
  const scene::Scene s = ring();
  const scene::Camera start = test::lookAtCamera({0.0f, 4.0f, 9.0f}, {0.0f, 0.0f, 0.0f});
  for (const char* method : {"sort-first", "sort-middle", "sort-last"}) {
    for (RegionStrategy regions : {RegionStrategy::StaticTiles, RegionStrategy::Dynamic}) {
      CAPTURE(method);
      CAPTURE(int(regions));
      SortOptions options;
      options.regions = regions;
      options.tileSizePx = 8;
      options.batchSize = 4;  // several geometry tasks, so both PEs send
      par::Runtime rt(2, "demand");
      std::unique_ptr<SortPoint> sortPoint = makeSortPoint(method);
      for (int frame = 0; frame < 3; ++frame) {
        const scene::Camera cam = orbitCamera(start, glm::vec3(0.0f), 6.2831853f * frame / 16.0f);
        renderFrame(*sortPoint, s, makeFrameView(cam, 40, 32), options, rt);
      }
      const std::vector<std::string_view>& expected = sortCounterNames(method);
      CHECK(sortCounterCount(rt.record()) == expected.size());  // no other sort point's counters
      for (std::string_view name : expected) {
        CAPTURE(name);
        const par::CounterRecord* c = findCounter(rt.record(), std::string(name));
        REQUIRE(c != nullptr);
        CHECK(c->perPe.size() == 2u);
      }
      // The "sent" counter agrees with the Channel that carried it, over all three frames.
      const SentChannel sent = sentChannel(method, regions);
      const double items = total(*findCounter(rt.record(), sent.counter));
      CHECK(items > 0.0);
      CHECK(uint64_t(items) * sent.itemBytes == test::channelTraffic(rt.record(), sent.channel).bytes);
      if (std::string(method) == "sort-last")
        CHECK(total(*findCounter(rt.record(), "Sort/composite_messages")) ==
              double(test::channelTraffic(rt.record(), "pixels").messages));
      // The runs are not empty: the equalities above compare real traffic.
      CHECK(total(*findCounter(rt.record(), std::string(expected[0]))) > 0.0);
      CHECK(total(*findCounter(rt.record(), std::string(expected[1]))) > 0.0);
    }
  }
}

TEST_CASE("SortCounters: sort-middle records each PE's own counters") {
  const scene::Scene s = test::threeTriangles();
  SortOptions options;
  options.regions = RegionStrategy::StaticStrips;
  options.batchSize = 1;  // balanced: PE 0 transforms triangles 0 and 1, PE 1 triangle 2
  par::Runtime rt(2, "balanced");
  renderParallel(s, test::tinyView(), "sort-middle", options, rt);
  // Triangle 0 -> owner 0 (kept), 1 -> owner 1 (sent by PE 0), 2 -> owners 0 (sent by PE 1)
  // and 1 (kept, a duplicate).
  const par::CounterRecord* routed = findCounter(rt.record(), "Sort/triangles_routed");
  const par::CounterRecord* sent = findCounter(rt.record(), "Sort/triangles_sent");
  const par::CounterRecord* duplicated = findCounter(rt.record(), "Sort/triangles_duplicated");
  REQUIRE(routed != nullptr);
  REQUIRE(sent != nullptr);
  REQUIRE(duplicated != nullptr);
  CHECK(routed->perPe == std::vector<double>{2.0, 2.0});
  CHECK(sent->perPe == std::vector<double>{1.0, 1.0});
  CHECK(duplicated->perPe == std::vector<double>{0.0, 1.0});
}

TEST_CASE("SortCounters: render --metrics writes the Sort/ counters the details line prints") {
  const auto dir = test::scratchDir("sort_counters_metrics");
  const std::string scene = (test::sourceDir() / "scenes" / "cornell.gltf").string();
  const test::CommandResult r = test::runParrender(
      "render \"" + scene + "\" -m sort-middle --threads 2 --frames 2 --orbit --width 48 --height 32 --quiet" +
      " --metrics \"" + (dir / "m.json").string() + "\" -o \"" + (dir / "x.png").string() + "\"");
  REQUIRE(r.exitStatus == 0);
  std::smatch printed;
  REQUIRE(std::regex_search(r.output, printed, std::regex(R"(triangles routed (\d+), sent (\d+), duplicated (\d+))")));
  const par::RunRecord record = par::readRunRecord(dir / "m.json");
  CHECK(sortCounterCount(record) == 3u);
  const char* names[] = {"Sort/triangles_routed", "Sort/triangles_sent", "Sort/triangles_duplicated"};
  for (int i = 0; i < 3; ++i) {
    CAPTURE(names[i]);
    const par::CounterRecord* c = findCounter(record, names[i]);
    REQUIRE(c != nullptr);
    CHECK(c->perPe.size() == 2u);
    CHECK(total(*c) == std::stod(printed[i + 1].str()));  // both are totals over the 2 frames
  }
  CHECK(std::stod(printed[1].str()) > 0.0);
  // The finished regions PE 1 sent to the assembler, as the record's results channels hold them.
  std::smatch results;
  REQUIRE(std::regex_search(r.output, results, std::regex(R"(regions to the assembler (\d+) messages \((\d+) bytes\))")));
  const test::ChannelSum sent = test::channelTraffic(record, "results");
  CHECK(sent.messages > 0u);
  CHECK(std::stoull(results[1].str()) == sent.messages);
  CHECK(std::stoull(results[2].str()) == sent.bytes);
}

}  // namespace
}  // namespace pr::raster
