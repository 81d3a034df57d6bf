// Helpers of the object-space and object-partitioning tests: render a scene with one of the
// partitioned tracers (returning image, run record and the tracer's figures), render the
// sequential reference, and check the run record's traffic invariants.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/partition/object_partition.h"
#include "raytrace/partition/object_space.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

namespace pr::test {

// Walls x = -3 (object 0) and x = +3 (object 1), two triangles each, reaching from z = 1 to
// z = -2000: seen from the origin, the left half of the image shows the left wall.
inline scene::Scene twoWalls() {
  scene::Scene s = emptyScene();
  for (float x : {-3.0f, 3.0f}) {
    scene::Object obj;
    obj.firstTriangle = uint32_t(s.triangles.size());
    obj.triangleCount = 2;
    addTriangle(s, {x, -100, 1}, {x, 100, 1}, {x, 100, -2000});
    addTriangle(s, {x, -100, 1}, {x, 100, -2000}, {x, -100, -2000});
    s.objects.push_back(obj);
  }
  return s;
}

// The partitioned tracer's figures as its run record holds them (Partition/ counters).
struct PartitionFigures {
  std::vector<uint64_t> geometryBytes;  // per PE
  std::vector<uint64_t> triangles;      // per PE: triangles held
  uint64_t raysSent = 0;                // rays (object-space) or ray queries (object) between PEs
  uint64_t hitsSent = 0;                // hit records sent back (object partitioning)
  int partitions = 0;                   // voxels or object pieces, over all PEs
};

inline PartitionFigures figuresFromRecord(const par::RunRecord& record) {
  PartitionFigures f;
  auto perPe = [&](const char* name) {
    std::vector<uint64_t> values;
    for (const par::CounterRecord& c : record.counters)
      if (c.name == name)
        for (double v : c.perPe) values.push_back(uint64_t(v));
    return values;
  };
  auto total = [&](const char* name) {
    uint64_t sum = 0;
    for (uint64_t v : perPe(name)) sum += v;
    return sum;
  };
  f.geometryBytes = perPe("Partition/geometry_bytes");
  f.triangles = perPe("Partition/triangles_held");
  f.raysSent = total("Partition/rays_sent") + total("Partition/ray_queries_sent");
  f.hitsSent = total("Partition/hit_replies_sent");
  f.partitions = int(total("Partition/partitions_owned"));
  return f;
}

struct PartitionedRun {
  image::Image image;
  rt::TraceResult result;
  par::RunRecord record;
  PartitionFigures figures;
};

inline rt::TraceOptions partitionedOptions(rt::IntegratorKind kind, int spp, int maxDepth = 5) {
  rt::TraceOptions opt;
  opt.integrator.kind = kind;
  opt.integrator.spp = spp;
  opt.integrator.maxDepth = maxDepth;
  opt.integrator.seed = 7;
  opt.tileSizePx = 8;
  return opt;
}

// partition: an rt::ObjectSpacePartition or rt::ObjectPartition.
template <class P>
PartitionedRun renderPartitioned(P& partition, const scene::Scene& s, const scene::Camera& cam, int w, int h,
                                 const rt::TraceOptions& opt, int pes, const std::string& schedule = "demand") {
  par::Runtime runtime(pes, schedule);
  PartitionedRun run;
  run.result = partition.render(rt::TraceJob{s, cam, w, h, opt}, runtime);
  run.image = run.result.image;
  run.record = runtime.record();
  run.figures = figuresFromRecord(run.record);
  return run;
}

inline image::Image renderSequential(const scene::Scene& s, const scene::Camera& cam, int w, int h,
                                     const rt::TraceOptions& opt) {
  par::Runtime runtime(1, "demand");
  return rt::renderRays(s, cam, w, h, opt, "sequential", runtime).image;
}

inline const par::StageRecord& traceStage(const par::RunRecord& record) {
  for (const par::StageRecord& st : record.stages)
    if (st.name == "trace") return st;
  FAIL("no trace stage in the run record");
  return record.stages.front();
}

// Bytes sent = bytes received, P = 1 moves nothing, and the tracer's per-kind ray counters
// agree with the messages the Channels counted.
inline void checkTraffic(const PartitionedRun& run, int pes, int batch = rt::kDefaultRayBatch) {
  const par::StageRecord& st = traceStage(run.record);
  uint64_t sent = 0, received = 0, bytesSent = 0, bytesReceived = 0;
  for (const par::PeStageRecord& pe : st.pes) {
    sent += pe.messagesSent;
    received += pe.messagesReceived;
    bytesSent += pe.bytesSent;
    bytesReceived += pe.bytesReceived;
    CHECK(pe.busySeconds <= st.wallSeconds * 1.0001 + 1e-4);
  }
  CHECK(sent == received);
  CHECK(bytesSent == bytesReceived);
  // Rays travel in batches of at most opt.rayBatch per message (all of them when it is 1).
  const uint64_t rays = run.figures.raysSent + run.figures.hitsSent;
  CHECK(sent <= rays);
  CHECK(sent * uint64_t(batch) >= rays);
  if (batch == 1) CHECK(sent == rays);
  for (const par::Traffic& t : st.traffic) CHECK(t.from != t.to);
  if (pes == 1) {
    CHECK(sent == 0);
    CHECK(bytesSent == 0);
    CHECK(st.traffic.empty());
  }
  CHECK(int(run.figures.geometryBytes.size()) == pes);
}

// Models without lights (Duck, BoxTextured) would render black, and a black frame proves no
// equivalence: a point light at the eye, bright enough for the scene's size, lights them.
inline void addHeadlightIfUnlit(scene::Scene& s, const scene::Camera& cam) {
  if (!s.lights.empty() || !s.areaLights.empty()) return;
  scene::PunctualLight light;
  light.position = cam.position();
  const float d = glm::length(s.bounds.extent()) + glm::length(cam.position() - s.bounds.center());
  light.intensity = 2.0f * d * d;
  s.lights.push_back(light);
}

// The scene and its cameras and punctual lights scaled by k about the origin (radiance from
// area lights does not depend on scale; punctual intensities are scaled by k^2 to match).
inline void scaleScene(scene::Scene& s, float k) {
  for (glm::vec3& p : s.positions) p *= k;
  s.bounds = scene::Bounds{};
  for (const glm::vec3& p : s.positions) s.bounds.extend(p);
  for (scene::Object& o : s.objects) o.bounds = scene::Bounds{k * o.bounds.min, k * o.bounds.max};
  for (scene::AreaLight& a : s.areaLights) a.area *= k * k;
  for (scene::PunctualLight& l : s.lights) {
    l.position *= k;
    l.intensity *= k * k;
    l.range *= k;
  }
  for (scene::Camera& c : s.cameras) {
    c.cameraToWorld[3] = glm::vec4(k * glm::vec3(c.cameraToWorld[3]), 1.0f);
    c.znear *= k;
    c.zfar *= k;
    c.xmag *= k;
    c.ymag *= k;
  }
}

inline std::filesystem::path bundledScene(const char* name) { return sourceDir() / "scenes" / name; }

}  // namespace pr::test
