// The ray tracing anchor: Intel Embree 3 (BVH8, build quality HIGH; shared/ANCHORS.md) over
// the same Scene triangles, tracing the same ray sets as parrender's ray tracers with single
// rays (rtcIntersect1 / rtcOccluded1). Ray benchmarks in tools/bench/ call it in the same run,
// print parrender / Embree ratios and compare hits ray by ray (t, primID).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"

namespace pr::bench {

struct RayIn {
  glm::vec3 org{0.0f};
  glm::vec3 dir{0.0f, 0.0f, -1.0f};  // need not be unit length; t is in units of |dir|
  float tmin = 0.0f;
  float tmax = std::numeric_limits<float>::infinity();
};

// The closest hit of one ray: primID is the index into Scene::triangles, kMiss when none.
struct HitOut {
  static constexpr uint32_t kMiss = UINT32_MAX;
  float t = std::numeric_limits<float>::infinity();
  uint32_t primID = kMiss;
  float u = 0.0f, v = 0.0f;  // barycentrics of vertices 1 and 2 (Embree's convention)
  bool hit() const { return primID != kMiss; }
};

struct TraceResult {
  double seconds = 0.0;       // wall clock of the whole trace (all threads, spawn to join)
  double mraysPerSecond = 0.0;
  // CPU time the tracing threads spent, summed: on a machine shared with other jobs the wall
  // clock also counts time they held the cores, so rays / CPU second is the steadier figure.
  double cpuSeconds = 0.0;
  double mraysPerCpuSecond = 0.0;
  int threads = 1;
  size_t rays = 0;
  size_t hitCount = 0;              // rays that hit (closest) or were occluded (occlusion)
  std::vector<HitOut> hits;         // traceClosest: one per ray, in ray order
  std::vector<uint8_t> occluded;    // traceOcclusion: 1 when something lies in (tmin, tmax)
};

// One Embree device and scene holding every triangle of a Scene as one triangle geometry, in
// Scene::triangles order, built with RTC_BUILD_QUALITY_HIGH at construction (timed).
// Tracing is const and may run from any number of threads at once.
class EmbreeAnchor {
 public:
  // buildThreads: Embree's worker threads for the BVH build (0 = all hardware threads). Embree
  // limits its TBB pool process-wide while the device lives.
  // Throws std::runtime_error when Embree cannot create the device or build the scene.
  explicit EmbreeAnchor(const scene::Scene& scene, int buildThreads = 1);
  ~EmbreeAnchor();
  EmbreeAnchor(const EmbreeAnchor&) = delete;
  EmbreeAnchor& operator=(const EmbreeAnchor&) = delete;

  double buildSeconds() const { return buildSeconds_; }
  size_t triangleCount() const { return triangleCount_; }

  // Closest hit of every ray with rtcIntersect1; `threads` threads each trace one contiguous
  // chunk of the rays (threads = 1: the calling thread alone). threads must be >= 1.
  TraceResult traceClosest(const std::vector<RayIn>& rays, int threads = 1) const;
  // Any hit in (tmin, tmax) with rtcOccluded1 (shadow rays), same threading.
  TraceResult traceOcclusion(const std::vector<RayIn>& rays, int threads = 1) const;

 private:
  void release();  // the scene, then the device (also when the constructor throws)

  void* device_ = nullptr;  // RTCDevice
  void* scene_ = nullptr;   // RTCScene
  double buildSeconds_ = 0.0;
  size_t triangleCount_ = 0;
};

// Primary rays through the pixel centres of a width x height image (row 0 = top), row-major,
// for the camera's projection at aspect width / height: each starts on the near plane and
// points through the pixel (unit direction), as the rasterizers see the scene.
std::vector<RayIn> primaryRays(const scene::Camera& camera, int width, int height);

}  // namespace pr::bench
