// bench_partitioned: the data-partitioned ray tracers (object-space, object partitioning) at
// P = 1 and P = 2 on the hot-spot scene and, when given, the 1M-triangle landscape: wall time
// of the whole render (best of N), each method's speed-up over its own P = 1 (target >= 1.6),
// ray messages per ray traced with the default batch against one ray per message (the
// unbatched tracers; target: at least 10x fewer), the effect of the batch size at P = 2, and
// a check that every image equals the sequential tracer's bit for bit. Then the image-space
// tracer with a data manager (image-space-cached): its P = 1 and P = 2 times beside
// image-space's, and at P = 2 the cache hit ratio, misses, prefetches, bytes fetched and time
// waiting for items for each cache size, and at simulated network latencies the wall time with
// and without latency hiding (a ray waiting for an item yields to the tile's other rays).
// Figures come from the runtime's run record; ratios are measured in the same run, P = 1 and
// P = 2 taking turns round by round.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/allocator.h"
#include "raytrace/partition/partition.h"

namespace {

using namespace pr;

struct Run {
  double seconds = 1e30;  // best wall time of the whole render (every stage)
  // best wall time of the render's call, also counting the controlling thread's set-up outside
  // the stages (films, integrator, the image's conversion)
  double callSeconds = 1e30;
  double messagesPerRay = 0.0;  // ray messages (rays, queries, replies) per ray traced
  double imbalance = 0.0;
  double splitSeconds = 0.0;  // the fastest render's stages: the data split (serial)
  double buildSeconds = 0.0;  // ... the owners' BVH builds (a stage, or the slowest set-up in the trace stage)
  double traceSeconds = 0.0;  // ... and the tracing (with the builds, where they are its set-up)
  bool sameImage = true;
};

// One render of `method` at P = pes, kept in `out` when it is the fastest so far.
void measureOnce(Run& out, const scene::Scene& s, const scene::Camera& cam, int w, int h, rt::TraceOptions opt,
                 const std::string& method, int pes, int batch, const image::Image& reference,
                 const std::string& schedule = "demand") {
  opt.rayBatch = batch;
  par::Runtime runtime(pes, schedule);
  const auto start = std::chrono::steady_clock::now();
  const rt::TraceResult result = rt::renderRays(s, cam, w, h, opt, method, runtime);
  const double call = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const par::RunRecord& record = runtime.record();
  out.sameImage = out.sameImage && result.image.pixels == reference.pixels;
  out.callSeconds = std::min(out.callSeconds, call);
  if (record.wallSeconds >= out.seconds) return;
  out.seconds = record.wallSeconds;
  uint64_t messages = 0;
  for (const par::StageRecord& st : record.stages)
    for (const par::ChannelTraffic& c : st.channels)
      if (c.kind == "rays") messages += c.messages;
  out.messagesPerRay = double(messages) / double(std::max<uint64_t>(1, result.rays.total()));
  for (size_t i = 0; i < record.stages.size(); ++i) {
    const par::StageRecord& st = record.stages[i];
    if (st.name == "split") out.splitSeconds = st.wallSeconds;
    if (st.name == "build") out.buildSeconds = st.wallSeconds;
    if (st.name == "trace") {
      out.traceSeconds = st.wallSeconds;
      for (const par::TaskSpan& span : record.timeline)
        if (span.stage == int(i) && span.task == par::kSetupSpan) out.buildSeconds = std::max(out.buildSeconds, span.end - span.start);
      double busiest = 0.0, mean = 0.0;
      for (const par::PeStageRecord& pe : st.pes) {
        busiest = std::max(busiest, pe.busySeconds);
        mean += pe.busySeconds / double(st.pes.size());
      }
      out.imbalance = mean > 0.0 ? busiest / mean - 1.0 : 0.0;
    }
  }
}

// The method at P = 1 and at P = 2 under each schedule, taking turns for `rounds` rounds, each
// the fastest of its rounds: a slow spell of a shared machine (the second core taken by another
// job for tens of seconds) then lands on both sides of the speed-up, not on P = 2's runs alone.
std::pair<Run, std::vector<Run>> measureP1P2(const scene::Scene& s, const scene::Camera& cam, int w, int h,
                                             const rt::TraceOptions& opt, const std::string& method, int rounds,
                                             const image::Image& reference, const std::vector<std::string>& schedules) {
  Run p1;
  std::vector<Run> p2(schedules.size());
  for (int r = 0; r < rounds; ++r) {
    measureOnce(p1, s, cam, w, h, opt, method, 1, rt::kDefaultRayBatch, reference);
    for (size_t i = 0; i < schedules.size(); ++i)
      measureOnce(p2[i], s, cam, w, h, opt, method, 2, rt::kDefaultRayBatch, reference, schedules[i]);
  }
  return {p1, p2};
}

int benchScene(const std::string& file, int w, int h, const rt::TraceOptions& opt, int repeats, const std::vector<int>& batches,
               const std::vector<std::string>& methods) {
  const scene::Scene s = scene::loadGltf(file);
  const scene::Camera cam = scene::selectCamera(s, "", float(w) / float(h));
  par::Runtime sequential(1, "demand");
  const image::Image reference = rt::renderRays(s, cam, w, h, opt, "sequential", sequential).image;
  std::printf("\n%s: %zu triangles, %dx%d, %s spp %d, best of %d\n", file.c_str(), s.triangles.size(), w, h,
              opt.integrator.kind == rt::IntegratorKind::Whitted ? "whitted" : "path", opt.integrator.spp, repeats);
  int failures = 0;
  // Demand-driven tiles, and preferred-bias, whose regions are the tiles' preferred PEs (the
  // owner of what their probe rays reach first, tile_affinity.h).
  const std::vector<std::string> schedules = {"demand", "preferred-bias"};
  for (const std::string& method : methods) {
    const auto [p1, p2s] = measureP1P2(s, cam, w, h, opt, method, repeats, reference, schedules);
    Run unbatched;
    measureOnce(unbatched, s, cam, w, h, opt, method, 2, 1, reference);
    bool same = p1.sameImage && unbatched.sameImage;
    for (size_t i = 0; i < schedules.size(); ++i) {
      const Run& p2 = p2s[i];
      same = same && p2.sameImage;
      const double speedup = p1.seconds / p2.seconds;
      std::printf("  %-12s %s: P=1 %.3f s, P=2 %.3f s: speed-up over its own P=1 %.2f (target >= 1.6), load imbalance %.3f\n",
                  method.c_str(), schedules[i].c_str(), p1.seconds, p2.seconds, speedup, p2.imbalance);
      std::printf("  %-12s %s: the whole call, with the set-up outside the stages: P=1 %.3f s, P=2 %.3f s: %.2f\n", method.c_str(),
                  schedules[i].c_str(), p1.callSeconds, p2.callSeconds, p1.callSeconds / std::max(1e-12, p2.callSeconds));
      // The build writes its BVHs into fresh memory and is bound by page faults, which vary
      // from run to run on a shared machine; the trace stage is the method's own parallel work.
      std::printf("  %-12s %s: stages of those runs: split P=1 %.3f s, P=2 %.3f s; build P=1 %.3f s, P=2 %.3f s (%.2f); trace P=1 %.3f s, P=2 %.3f s (%.2f)\n",
                  method.c_str(), schedules[i].c_str(), p1.splitSeconds, p2.splitSeconds, p1.buildSeconds, p2.buildSeconds,
                  p1.buildSeconds / std::max(1e-12, p2.buildSeconds), p1.traceSeconds, p2.traceSeconds,
                  p1.traceSeconds / std::max(1e-12, p2.traceSeconds));
      const double fewer = unbatched.messagesPerRay / std::max(1e-12, p2.messagesPerRay);
      std::printf("  %-12s %s: ray messages per ray at P=2: %.4f with batch %d, %.4f one ray per message (demand): %.1fx fewer (target >= 10)\n",
                  method.c_str(), schedules[i].c_str(), p2.messagesPerRay, rt::kDefaultRayBatch, unbatched.messagesPerRay, fewer);
    }
    std::printf("  %-12s batch size at P=2 (demand):", method.c_str());
    for (int batch : batches) {
      Run b;
      measureOnce(b, s, cam, w, h, opt, method, 2, batch, reference);
      same = same && b.sameImage;
      std::printf("  %d: %.3f s %.4f msg/ray", batch, b.seconds, b.messagesPerRay);
    }
    std::printf("\n  %-12s images %s the sequential tracer's\n", method.c_str(), same ? "bit-identical to" : "DIFFER from");
    failures += same ? 0 : 1;
  }
  return failures;
}

double counterTotal(const par::RunRecord& record, const std::string& name) {
  double sum = 0.0;
  for (const par::CounterRecord& c : record.counters)
    if (c.name == name)
      for (double v : c.perPe) sum += v;
  return sum;
}

int benchCached(const std::string& file, int w, int h, rt::TraceOptions opt, int repeats, const std::vector<double>& cacheMb,
                const std::vector<double>& latencyUs) {
  const scene::Scene s = scene::loadGltf(file);
  const scene::Camera cam = scene::selectCamera(s, "", float(w) / float(h));
  par::Runtime sequential(1, "demand");
  const image::Image reference = rt::renderRays(s, cam, w, h, opt, "sequential", sequential).image;
  std::printf("\n%s: image-space-cached (data manager), %dx%d, best of %d\n", file.c_str(), w, h, repeats);
  const auto [world1, worlds2] = measureP1P2(s, cam, w, h, opt, "image-space", repeats, reference, {"demand"});
  const auto [cached1, cacheds2] = measureP1P2(s, cam, w, h, opt, "image-space-cached", repeats, reference, {"demand"});
  const Run& world2 = worlds2.front();
  const Run& cached2 = cacheds2.front();
  std::printf("  image-space        P=1 %.3f s, P=2 %.3f s, speed-up %.2f\n", world1.seconds, world2.seconds, world1.seconds / world2.seconds);
  std::printf("  image-space-cached P=1 %.3f s, P=2 %.3f s, speed-up %.2f; P=1 time / image-space's %.2f\n", cached1.seconds,
              cached2.seconds, cached1.seconds / cached2.seconds, cached1.seconds / world1.seconds);
  bool same = world1.sameImage && world2.sameImage && cached1.sameImage && cached2.sameImage;
  std::printf("  %10s %9s %10s %10s %10s %12s %9s %9s\n", "cache MiB", "time s", "hit ratio", "misses", "prefetch",
              "fetched MB", "wait s", "held MB");
  for (double mb : cacheMb) {
    opt.cacheBytes = std::size_t(mb * 1048576.0);
    par::Runtime runtime(2, "demand");
    const rt::TraceResult result = rt::renderRays(s, cam, w, h, opt, "image-space-cached", runtime);
    const par::RunRecord& record = runtime.record();
    same = same && result.image.pixels == reference.pixels;
    const double hits = counterTotal(record, "Cache/hits"), misses = counterTotal(record, "Cache/misses");
    const double joined = counterTotal(record, "Cache/misses_joined");
    double fetched = 0.0, wait = 0.0;
    for (const par::StageRecord& st : record.stages) {
      for (const par::ChannelTraffic& c : st.channels)
        if (c.kind == "data") fetched += double(c.bytes);
      if (st.name == "trace")
        for (const par::PeStageRecord& pe : st.pes) wait += pe.messageWaitSeconds;
    }
    std::printf("  %10.3f %9.3f %10.4f %10.0f %10.0f %12.2f %9.4f %9.2f\n", mb, record.wallSeconds,
                hits + misses + joined > 0 ? hits / (hits + misses + joined) : 1.0, misses, counterTotal(record, "Cache/prefetches"), fetched * 1e-6,
                wait, counterTotal(record, "Cache/bytes_held_at_end") * 1e-6);
  }
  // Profiling (seed section 4.5.3): what each prefetch policy gains at a simulated latency with
  // a cache of two items' size, and the schedules that take their costs from the profile
  // pre-pass. Best of `repeats` wall times; the counters are the best run's.
  {
    rt::TraceOptions p = opt;
    p.cacheBytes = std::size_t{4} << 20;
    p.dataLatencySeconds = 50e-6;
    std::printf("  profiling at P=2, 4 MiB cache, 50 us latency:\n  %-24s %9s %10s %8s %10s %9s %9s\n", "prefetch / schedule",
                "time s", "hit ratio", "misses", "prefetch", "used", "wait s");
    struct Policy {
      const char* label;
      rt::TraceOptions::Prefetch prefetch;
      const char* schedule;
    };
    for (const Policy& pol : {Policy{"none / demand", rt::TraceOptions::Prefetch::None, "demand"},
                              Policy{"camera / demand", rt::TraceOptions::Prefetch::CameraRays, "demand"},
                              Policy{"profile / demand", rt::TraceOptions::Prefetch::Profile, "demand"},
                              Policy{"profile / unbalanced", rt::TraceOptions::Prefetch::Profile, "unbalanced"},
                              Policy{"profile / hot-spots", rt::TraceOptions::Prefetch::Profile, "hot-spots"}}) {
      p.prefetch = pol.prefetch;
      double best = 1e300;
      par::RunRecord bestRecord;
      for (int r = 0; r < repeats; ++r) {
        par::Runtime runtime(2, pol.schedule);
        const rt::TraceResult result = rt::renderRays(s, cam, w, h, p, "image-space-cached", runtime);
        same = same && result.image.pixels == reference.pixels;
        if (runtime.record().wallSeconds < best) {
          best = runtime.record().wallSeconds;
          bestRecord = runtime.record();
        }
      }
      const double hits = counterTotal(bestRecord, "Cache/hits"), misses = counterTotal(bestRecord, "Cache/misses");
      const double joined = counterTotal(bestRecord, "Cache/misses_joined");
      double wait = 0.0;
      for (const par::StageRecord& st : bestRecord.stages)
        for (const par::PeStageRecord& pe : st.pes) wait += pe.messageWaitSeconds;
      std::printf("  %-24s %9.3f %10.4f %8.0f %10.0f %9.0f %9.4f\n", pol.label, best,
                  hits + misses + joined > 0 ? hits / (hits + misses + joined) : 1.0, misses,
                  counterTotal(bestRecord, "Cache/prefetches"), counterTotal(bestRecord, "Cache/prefetches_used"), wait);
    }
  }
  // Latency hiding at a simulated network latency: a cache that misses often (1 MiB), the
  // tile's rays as threads against every ray waiting for its item.
  opt.cacheBytes = std::size_t{1} << 20;
  std::printf("  simulated latency at P=2, 1 MiB cache: wall time with latency hiding / waiting for each item\n");
  for (double us : latencyUs) {
    double seconds[2] = {0.0, 0.0}, wait[2] = {0.0, 0.0};
    for (int hide = 0; hide < 2; ++hide) {
      opt.dataLatencySeconds = us * 1e-6;
      opt.hideLatency = hide == 1;
      par::Runtime runtime(2, "demand");
      const rt::TraceResult result = rt::renderRays(s, cam, w, h, opt, "image-space-cached", runtime);
      same = same && result.image.pixels == reference.pixels;
      seconds[hide] = runtime.record().wallSeconds;
      for (const par::StageRecord& st : runtime.record().stages)
        if (st.name == "trace")
          for (const par::PeStageRecord& pe : st.pes) wait[hide] += pe.messageWaitSeconds;
    }
    std::printf("  %8.0f us: %8.3f s (waiting %.3f s) / %8.3f s (waiting %.3f s): %.1fx faster\n", us, seconds[1], wait[1],
                seconds[0], wait[0], seconds[0] / seconds[1]);
  }
  std::printf("  images %s the sequential tracer's\n", same ? "bit-identical to" : "DIFFER from");
  return same ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  pr::retainFreedMemory();
  CLI::App app{"bench_partitioned: object-space and object partitioning at P = 1 and 2, ray batches and messages per ray"};
  std::vector<std::string> scenes = {std::string(PARRENDER_SOURCE_DIR) + "/scenes/hotspot.gltf"};
  int width = 384, height = 384, spp = 2, repeats = 3;
  std::string integrator = "path";
  std::vector<int> batches = {1, 4, 16, 64, 256, 1024};
  app.add_option("--scenes", scenes, "scenes (e.g. scenes/hotspot.gltf build/scenes/landscape.glb)")->capture_default_str();
  app.add_option("--width", width)->check(CLI::Range(8, 8192))->capture_default_str();
  app.add_option("--height", height)->check(CLI::Range(8, 8192))->capture_default_str();
  app.add_option("--spp", spp)->check(CLI::Range(1, 1024))->capture_default_str();
  app.add_option("--repeats", repeats, "best of N runs")->check(CLI::Range(1, 100))->capture_default_str();
  app.add_option("--integrator", integrator)->check(CLI::IsMember({"whitted", "path"}))->capture_default_str();
  app.add_option("--batches", batches, "batch sizes of the sweep at P = 2")->check(CLI::Range(1, rt::kMaxRayBatch));
  std::vector<double> cacheMb = {0.0, 0.0625, 0.25, 1.0, 4.0, 64.0};
  std::vector<double> latencyUs = {0.0, 50.0, 200.0};
  app.add_option("--latency-us", latencyUs, "image-space-cached: simulated one-way latencies of the latency-hiding runs, microseconds")
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--cache-mb", cacheMb, "image-space-cached: cache sizes of the sweep at P = 2, MiB")->check(CLI::Range(0.0, 1048576.0));
  std::vector<std::string> methods = {"object-space", "object", "image-space-cached"};
  app.add_option("--methods", methods, "the methods to measure")
      ->check(CLI::IsMember({"object-space", "object", "image-space-cached"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    rt::TraceOptions opt;
    opt.integrator.kind = integrator == "whitted" ? rt::IntegratorKind::Whitted : rt::IntegratorKind::Path;
    opt.integrator.spp = spp;
    std::printf("bench_partitioned on %u hardware threads\n", std::thread::hardware_concurrency());
    std::vector<std::string> partitioned;
    for (const std::string& m : methods)
      if (m != "image-space-cached") partitioned.push_back(m);
    int failures = 0;
    if (!partitioned.empty())
      for (const std::string& f : scenes) failures += benchScene(f, width, height, opt, repeats, batches, partitioned);
    if (partitioned.size() < methods.size())
      for (const std::string& f : scenes) failures += benchCached(f, width, height, opt, repeats, cacheMb, latencyUs);
    return failures == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_partitioned: %s\n", e.what());
    return 1;
  }
}
