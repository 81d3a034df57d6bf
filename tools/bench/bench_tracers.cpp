// bench_tracers: the ray tracers' performance figures (outside ctest). Image-space parallel
// efficiency at P = 1 vs P = 2 with demand-driven tiles on the hot-spot scene (target >= 95%),
// read from the runtime's RunRecord; and, when the Embree anchor is built, primary, shadow and
// diffuse-bounce ray throughput of the ray tracing core against Embree 3 on the same rays in
// the same run (ratios printed; target on the 1M-triangle scenes: primary, shadow and diffuse
// rays each >= 0.8x Embree, BVH build within 1.5x Embree's time).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/parallel/metrics.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/allocator.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/sampling.h"
#include "raytrace/partition/partition.h"
#ifdef PARRENDER_HAVE_EMBREE_ANCHOR
#include "tools/bench/anchors/embree_anchor.h"
#endif

namespace {

using namespace pr;

[[maybe_unused]] double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Best of `repeats` wall times of the trace stage (the RunRecord's), image-space, demand tiles.
double imageSpaceSeconds(const scene::Scene& s, const scene::Camera& cam, const rt::Bvh& bvh, int w, int h, int pes,
                         int repeats, const rt::TraceOptions& base) {
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    rt::TraceOptions opt = base;
    opt.worldBvh = &bvh;
    par::Runtime runtime(pes, "demand");
    rt::renderRays(s, cam, w, h, opt, "image-space", runtime);
    best = std::min(best, runtime.record().wallSeconds);
  }
  return best;
}

#ifdef PARRENDER_HAVE_EMBREE_ANCHOR
// Our closest-hit (or any-hit) throughput on the same rays, on `threads` threads each taking a
// contiguous chunk, as the anchor does.
double ourMrays(const rt::Bvh& bvh, const std::vector<bench::RayIn>& rays, int threads, bool occlusion) {
  std::vector<rt::Ray> ours(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) ours[i] = rt::Ray{rays[i].org, rays[i].tmin, rays[i].dir, rays[i].tmax};
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  std::vector<size_t> hits(size_t(threads), 0);
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      const size_t lo = ours.size() * size_t(t) / size_t(threads), hi = ours.size() * size_t(t + 1) / size_t(threads);
      // A local count: one shared cache line of counters written per ray would cost P > 1 more
      // than the tracing it measures.
      size_t count = 0;
      for (size_t i = lo; i < hi; ++i) {
        rt::Hit hit;
        count += occlusion ? bvh.occluded(ours[i]) : bvh.intersect(ours[i], hit);
      }
      hits[size_t(t)] = count;
    });
  for (std::thread& t : pool) t.join();
  return double(rays.size()) / seconds(start) * 1e-6;
}

// Shadow rays from the primary hits towards a point above the scene's centre, and diffuse
// bounce rays (cosine-distributed about the normal) from the same hits.
void secondaryRays(const scene::Scene& s, const std::vector<bench::RayIn>& primary, const bench::EmbreeAnchor& anchor,
                   std::vector<bench::RayIn>& shadow, std::vector<bench::RayIn>& diffuse) {
  const bench::TraceResult hits = anchor.traceClosest(primary, 1);
  const glm::vec3 lamp = s.bounds.center() + glm::vec3(0.0f, 0.6f * s.bounds.extent().y + 1e-3f, 0.0f);
  for (size_t i = 0; i < primary.size(); ++i) {
    const bench::HitOut& h = hits.hits[i];
    if (!h.hit()) continue;
    const rt::Ray ray{primary[i].org, primary[i].tmin, primary[i].dir, primary[i].tmax};
    const rt::SurfaceInteraction si = rt::makeInteraction(s, ray, rt::Hit{h.t, h.primID, h.u, h.v});
    const rt::Ray toLamp = rt::spawnRayTo(si, lamp);
    shadow.push_back({toLamp.origin, toLamp.direction, toLamp.tMin, toLamp.tMax});
    const glm::vec3 n = si.frontFace ? si.geometricNormal : -si.geometricNormal;
    const glm::vec3 d = rt::Frame(n).toWorld(rt::cosineHemisphere(rt::sample1D(1, uint32_t(i), 0, 1, 0), rt::sample1D(1, uint32_t(i), 0, 1, 1)));
    const rt::Ray bounce = rt::spawnRay(si, d);
    diffuse.push_back({bounce.origin, bounce.direction, bounce.tMin, bounce.tMax});
  }
}

// Rays per second of the best of `repeats` passes, ours and Embree's taking turns, so both
// see the same state of a shared machine.
void embreeComparison(const std::string& file, int w, int h, int repeats) {
  const scene::Scene s = scene::loadGltf(file);
  const scene::Camera cam = scene::selectCamera(s, "", float(w) / float(h));
  auto start = std::chrono::steady_clock::now();
  const rt::Bvh bvh(s);
  const double ourBuild = seconds(start);
  const bench::EmbreeAnchor anchor(s, 1);
  std::printf("\n%s: %zu triangles; BVH build %.3f s, Embree %.3f s, ours / Embree time %.2f (target <= 1.5)\n",
              file.c_str(), s.triangles.size(), ourBuild, anchor.buildSeconds(), ourBuild / anchor.buildSeconds());
  const std::vector<bench::RayIn> primary = bench::primaryRays(cam, w, h);
  std::vector<bench::RayIn> shadow, diffuse;
  secondaryRays(s, primary, anchor, shadow, diffuse);
  struct Set {
    const char* name;
    const std::vector<bench::RayIn>* rays;
    bool occlusion;
  };
  for (const Set& set : {Set{"primary", &primary, false}, Set{"shadow", &shadow, true}, Set{"diffuse", &diffuse, false}})
    for (int threads : {1, 2}) {
      double embree = 0.0, ours = 0.0;
      for (int r = 0; r < repeats; ++r) {
        const bench::TraceResult e = set.occlusion ? anchor.traceOcclusion(*set.rays, threads) : anchor.traceClosest(*set.rays, threads);
        embree = std::max(embree, e.mraysPerSecond);
        ours = std::max(ours, ourMrays(bvh, *set.rays, threads, set.occlusion));
      }
      std::printf("  %-8s P=%d %8zu rays: ours %7.2f Mrays/s, Embree %7.2f Mrays/s, ours / Embree %.2f (target >= 0.8)\n", set.name, threads,
                  set.rays->size(), ours, embree, ours / embree);
    }
}
#endif

}  // namespace

int main(int argc, char** argv) {
  pr::retainFreedMemory();
  CLI::App app{"bench_tracers: image-space parallel efficiency and ray throughput against Embree"};
  std::string hotspot = std::string(PARRENDER_SOURCE_DIR) + "/scenes/hotspot.gltf";
  std::vector<std::string> embreeScenes = {std::string(PARRENDER_SOURCE_DIR) + "/scenes/hotspot.gltf",
                                           std::string(PARRENDER_SOURCE_DIR) + "/scenes/cornell.gltf"};
  int width = 256, height = 256, spp = 2, repeats = 3, rayWidth = 1024, rayHeight = 768;
  std::string integrator = "path";
  app.add_option("--scene", hotspot, "scene of the efficiency run");
  app.add_option("--embree-scenes", embreeScenes, "scenes of the Embree comparison (e.g. build/scenes/landscape.glb)");
  app.add_option("--width", width)->check(CLI::Range(8, 8192));
  app.add_option("--height", height)->check(CLI::Range(8, 8192));
  app.add_option("--spp", spp)->check(CLI::Range(1, 1024));
  app.add_option("--repeats", repeats, "best of N runs")->check(CLI::Range(1, 100));
  app.add_option("--ray-width", rayWidth, "primary rays of the Embree comparison: image width")->check(CLI::Range(8, 8192));
  app.add_option("--ray-height", rayHeight, "... and height")->check(CLI::Range(8, 8192));
  app.add_option("--integrator", integrator)->check(CLI::IsMember({"whitted", "path"}));
  CLI11_PARSE(app, argc, argv);

  try {
    const scene::Scene s = scene::loadGltf(hotspot);
    const scene::Camera cam = scene::selectCamera(s, "", float(width) / float(height));
    const rt::Bvh bvh(s);
    rt::TraceOptions opt;
    opt.integrator.kind = integrator == "whitted" ? rt::IntegratorKind::Whitted : rt::IntegratorKind::Path;
    opt.integrator.spp = spp;
    const double t1 = imageSpaceSeconds(s, cam, bvh, width, height, 1, repeats, opt);
    const double t2 = imageSpaceSeconds(s, cam, bvh, width, height, 2, repeats, opt);
    const double efficiency = t1 / (2.0 * t2);
    std::printf("image-space, demand-driven %dx%d tiles, %s %dx%d spp %d (%s): T1 %.3f s, T2 %.3f s, speed-up %.3f, "
                "efficiency %.1f%% (target >= 95%%) on %u hardware threads\n",
                opt.tileSizePx, opt.tileSizePx, integrator.c_str(), width, height, spp, hotspot.c_str(), t1, t2, t1 / t2,
                100.0 * efficiency, std::thread::hardware_concurrency());
#ifdef PARRENDER_HAVE_EMBREE_ANCHOR
    for (const std::string& f : embreeScenes) embreeComparison(f, rayWidth, rayHeight, repeats);
#else
    std::printf("Embree anchor not built (tools/setup.sh --bench): no throughput ratios\n");
#endif
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_tracers: %s\n", e.what());
    return 1;
  }
  return 0;
}
