// Embree ray tracing anchor (see embree_anchor.h): one RTCDevice and one RTCScene per
// EmbreeAnchor, one triangle geometry holding the Scene's vertex and index arrays as they are,
// so Embree's primID is parrender's triangle index and hits compare one to one.
#include "tools/bench/anchors/embree_anchor.h"

#include <chrono>
#include <ctime>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <embree3/rtcore.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

namespace pr::bench {
namespace {

using Clock = std::chrono::steady_clock;

// The first error Embree reported on a device; build and trace check it afterwards.
void recordError(void* userPtr, RTCError code, const char* message) {
  auto* first = static_cast<std::string*>(userPtr);
  if (first->empty()) first->append("Embree error " + std::to_string(int(code)) + ": " + (message ? message : ""));
}

// Embree's guidance: denormals flushed to zero on every tracing thread (its kernels assume
// it for speed). Restored on scope exit so the caller's floating-point state is untouched.
class FlushDenormals {
 public:
  FlushDenormals() : saved_(_mm_getcsr()) {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  }
  ~FlushDenormals() { _mm_setcsr(saved_); }
 private:
  unsigned saved_;
};

void closestChunk(RTCScene scene, const RayIn* rays, HitOut* hits, size_t count) {
  FlushDenormals ftz;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (size_t i = 0; i < count; ++i) {
    const RayIn& in = rays[i];
    RTCRayHit rh;
    rh.ray.org_x = in.org.x, rh.ray.org_y = in.org.y, rh.ray.org_z = in.org.z;
    rh.ray.dir_x = in.dir.x, rh.ray.dir_y = in.dir.y, rh.ray.dir_z = in.dir.z;
    rh.ray.tnear = in.tmin;
    rh.ray.tfar = in.tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = UINT32_MAX;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    HitOut& out = hits[i];
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      out.t = rh.ray.tfar;
      out.primID = rh.hit.primID;
      out.u = rh.hit.u;
      out.v = rh.hit.v;
    } else {
      out = HitOut{};
    }
  }
}

void occlusionChunk(RTCScene scene, const RayIn* rays, uint8_t* occluded, size_t count) {
  FlushDenormals ftz;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (size_t i = 0; i < count; ++i) {
    const RayIn& in = rays[i];
    RTCRay ray;
    ray.org_x = in.org.x, ray.org_y = in.org.y, ray.org_z = in.org.z;
    ray.dir_x = in.dir.x, ray.dir_y = in.dir.y, ray.dir_z = in.dir.z;
    ray.tnear = in.tmin;
    ray.tfar = in.tmax;
    ray.time = 0.0f;
    ray.mask = UINT32_MAX;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(scene, &context, &ray);
    occluded[i] = ray.tfar < 0.0f ? 1 : 0;  // Embree sets tfar = -inf on an occlusion
  }
}

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Runs chunk(first, count) over `threads` contiguous chunks of n items and fills the
// result's timing: wall clock from spawn to join, CPU time summed over the chunks.
template <typename Chunk>
void runChunked(size_t n, int threads, TraceResult& result, Chunk chunk) {
  if (threads < 1) throw std::invalid_argument("Embree anchor: threads must be >= 1, got " + std::to_string(threads));
  std::vector<double> cpu(size_t(threads), 0.0);
  const auto timedChunk = [&](int t) {
    const size_t first = n * size_t(t) / size_t(threads), last = n * size_t(t + 1) / size_t(threads);
    const double cpuStart = threadCpuSeconds();
    chunk(first, last - first);
    cpu[size_t(t)] = threadCpuSeconds() - cpuStart;
  };
  const auto start = Clock::now();
  if (threads == 1) {
    timedChunk(0);
  } else {
    std::vector<std::thread> workers;
    workers.reserve(size_t(threads));
    for (int t = 0; t < threads; ++t) workers.emplace_back(timedChunk, t);
    for (std::thread& w : workers) w.join();
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.rays = n;
  result.threads = threads;
  for (double c : cpu) result.cpuSeconds += c;
  result.mraysPerSecond = result.seconds > 0.0 ? double(n) / result.seconds * 1e-6 : 0.0;
  result.mraysPerCpuSecond = result.cpuSeconds > 0.0 ? double(n) / result.cpuSeconds * 1e-6 : 0.0;
}

}  // namespace

EmbreeAnchor::EmbreeAnchor(const scene::Scene& scene, int buildThreads) : triangleCount_(scene.triangles.size()) {
  if (buildThreads < 0)
    throw std::invalid_argument("Embree anchor: build threads must be >= 0, got " + std::to_string(buildThreads));
  const std::string config = buildThreads > 0 ? "threads=" + std::to_string(buildThreads) : std::string();
  RTCDevice device = rtcNewDevice(config.c_str());
  if (!device) throw std::runtime_error("Embree anchor: rtcNewDevice failed (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  device_ = device;
  std::string error;
  rtcSetDeviceErrorFunction(device, recordError, &error);

  // The build is timed from the copy of the arrays into Embree's buffers to rtcCommitScene.
  const auto start = Clock::now();
  RTCScene rtcScene = rtcNewScene(device);
  scene_ = rtcScene;
  rtcSetSceneBuildQuality(rtcScene, RTC_BUILD_QUALITY_HIGH);
  if (!scene.triangles.empty()) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_HIGH);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), scene.positions.size()));
    auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                    3 * sizeof(uint32_t), scene.triangles.size()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      release();
      throw std::runtime_error("Embree anchor: cannot allocate geometry buffers (" + error + ")");
    }
    for (size_t i = 0; i < scene.positions.size(); ++i) {
      vertices[3 * i + 0] = scene.positions[i].x;
      vertices[3 * i + 1] = scene.positions[i].y;
      vertices[3 * i + 2] = scene.positions[i].z;
    }
    for (size_t i = 0; i < scene.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) indices[3 * i + size_t(k)] = scene.triangles[i].v[k];
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(rtcScene, geometry, 0);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(rtcScene);
  buildSeconds_ = std::chrono::duration<double>(Clock::now() - start).count();
  rtcSetDeviceErrorFunction(device, nullptr, nullptr);
  if (!error.empty()) {
    release();
    throw std::runtime_error("Embree anchor: scene build failed: " + error);
  }
}

EmbreeAnchor::~EmbreeAnchor() { release(); }

void EmbreeAnchor::release() {
  if (scene_) rtcReleaseScene(static_cast<RTCScene>(scene_));
  if (device_) rtcReleaseDevice(static_cast<RTCDevice>(device_));
  scene_ = device_ = nullptr;
}

TraceResult EmbreeAnchor::traceClosest(const std::vector<RayIn>& rays, int threads) const {
  TraceResult result;
  result.hits.resize(rays.size());
  auto scene = static_cast<RTCScene>(scene_);
  runChunked(rays.size(), threads, result, [&](size_t first, size_t count) {
    closestChunk(scene, rays.data() + first, result.hits.data() + first, count);
  });
  for (const HitOut& h : result.hits) result.hitCount += h.hit() ? 1 : 0;
  return result;
}

TraceResult EmbreeAnchor::traceOcclusion(const std::vector<RayIn>& rays, int threads) const {
  TraceResult result;
  result.occluded.resize(rays.size());
  auto scene = static_cast<RTCScene>(scene_);
  runChunked(rays.size(), threads, result, [&](size_t first, size_t count) {
    occlusionChunk(scene, rays.data() + first, result.occluded.data() + first, count);
  });
  for (uint8_t o : result.occluded) result.hitCount += o;
  return result;
}

}  // namespace pr::bench
