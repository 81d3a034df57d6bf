// Helpers for the sort-point tests: the table of sort-point configurations, the hand-checked
// three-triangle scene and sums over the runtime's run record (stage traffic, channel traffic
// by kind or name, named counters).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "common/parallel/runtime.h"
#include "raster/raster_test_scenes.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/geometry.h"
#include "run_record_support.h"

namespace pr::test {

// Every sort point with every region assignment or compositor it takes: the rows of the
// equivalence table and of the result-traffic checks.
struct SortRow {
  const char* method;
  raster::RegionStrategy regions;
  const char* compositor;
  bool sparse;
};
inline constexpr SortRow kSortRows[] = {
    {"sort-first", raster::RegionStrategy::StaticStrips, "direct-send", false},
    {"sort-first", raster::RegionStrategy::StaticTiles, "direct-send", false},
    {"sort-first", raster::RegionStrategy::Dynamic, "direct-send", false},
    {"sort-middle", raster::RegionStrategy::StaticStrips, "direct-send", false},
    {"sort-middle", raster::RegionStrategy::StaticTiles, "direct-send", false},
    {"sort-middle", raster::RegionStrategy::Dynamic, "direct-send", false},
    {"sort-last", raster::RegionStrategy::StaticTiles, "direct-send", false},
    {"sort-last", raster::RegionStrategy::StaticTiles, "direct-send", true},
    {"sort-last", raster::RegionStrategy::StaticTiles, "binary-swap", false},  // P a power of two only
    {"sort-last", raster::RegionStrategy::StaticTiles, "binary-swap", true},
};

// 16 x 16 pixels through pixelOrthoCamera (pixel row j has its sample at world y = 7.5 - j).
// Triangle 0 covers rows 2..5 only (top strip), triangle 1 rows 10..13 only (bottom strip),
// triangle 2 rows 2..13 (both strips). All counter-clockwise, facing the camera.
inline constexpr int kTinySize = 16;
inline scene::Scene threeTriangles() {
  scene::Scene s = emptyScene();
  addTriangle(s, {-6, 6, 0}, {-6, 2, 0}, {-2, 6, 0});
  addTriangle(s, {-6, -2, 0}, {-6, -6, 0}, {-2, -2, 0});
  addTriangle(s, {2, 6, 0}, {2, -6, 0}, {6, 6, 0});
  return s;
}
inline raster::FrameView tinyView() { return raster::makeFrameView(pixelOrthoCamera(kTinySize), kTinySize, kTinySize); }

struct StageTraffic {
  uint64_t messagesSent = 0, bytesSent = 0, messagesReceived = 0, bytesReceived = 0;
};

// Sums over the stages whose name starts with prefix (all stages for ""), over all PEs or one.
inline StageTraffic stageTraffic(const par::RunRecord& record, const std::string& prefix, int pe = -1) {
  StageTraffic t;
  for (const par::StageRecord& s : record.stages) {
    if (s.name.rfind(prefix, 0) != 0) continue;
    for (size_t p = 0; p < s.pes.size(); ++p) {
      if (pe >= 0 && int(p) != pe) continue;
      t.messagesSent += s.pes[p].messagesSent;
      t.bytesSent += s.pes[p].bytesSent;
      t.messagesReceived += s.pes[p].messagesReceived;
      t.bytesReceived += s.pes[p].bytesReceived;
    }
  }
  return t;
}

struct ChannelSum {
  uint64_t messages = 0, bytes = 0;
};

// Traffic between PEs through the channels whose kind ("results", "primitives", "pixels",
// "requests", "data") or name equals what, over the stages whose name starts with prefix.
inline ChannelSum channelTraffic(const par::RunRecord& record, const std::string& what, const std::string& prefix = "") {
  ChannelSum sum;
  for (const par::StageRecord& s : record.stages) {
    if (s.name.rfind(prefix, 0) != 0) continue;
    for (const par::ChannelTraffic& c : s.channels) {
      if (c.kind != what && c.name != what) continue;
      sum.messages += c.messages;
      sum.bytes += c.bytes;
    }
  }
  return sum;
}

// Every counter of the record summed over PEs, by name.
using CounterTotals = std::map<std::string, double>;
inline CounterTotals counterTotals(const par::RunRecord& record) {
  CounterTotals totals;
  for (const par::CounterRecord& c : record.counters)
    for (double v : c.perPe) totals[c.name] += v;
  return totals;
}

// What one frame added to each counter: render it with fn, compare totals before and after.
template <class Fn>
CounterTotals frameCounters(const par::Runtime& rt, Fn&& fn) {
  const CounterTotals before = counterTotals(rt.record());
  fn();
  CounterTotals after = counterTotals(rt.record());
  for (auto& [name, value] : after) {
    const auto it = before.find(name);
    if (it != before.end()) value -= it->second;
  }
  return after;
}

}  // namespace pr::test
