// bench_photonmap: the photon map's storage and search (photonmap/): bytes per photon, kd-tree
// build time for 1M photons on one thread and on the runtime at P = 2 (and P = cores), and
// k = 50 nearest-photon queries per second on one thread, beside nanoflann (Debian
// libnanoflann-dev, tools/setup.sh --bench) on the same points in the same run when CMake found
// it. Not part of ctest. The photons lie on the walls of a Cornell-like box with a bright
// caustic-like blob on the floor (the density varies 20:1, as in a real map); queries are at
// surface points near stored photons, as a renderer makes them. Last, photon tracing (pass 1)
// on the bundled Cornell box: photons emitted per second per PE at P = 1 and P = 2.
//   bench_photonmap [--photons N] [--queries N] [--k N] [--radius R] [--repeat N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "common/parallel/runtime.h"
#include "common/scene/gltf_loader.h"
#include "common/util/allocator.h"
#include "photonmap/density_estimate.h"
#include "photonmap/kd_tree.h"
#include "photonmap/photon.h"
#include "photonmap/photon_tracer.h"
#include "raytrace/core/bvh.h"

#ifdef PARRENDER_HAVE_NANOFLANN
#include <nanoflann.hpp>
#endif

namespace {

using pr::pm::KdTree;
using pr::pm::NearestPhotons;
using pr::pm::Photon;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// CPU time of this thread (the query figures are single-threaded; on a shared machine the wall
// clock also counts other jobs). Both are printed for the build, which uses several threads.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Rng {  // splitmix64
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float uniform() { return float(next() >> 40) * 0x1p-24f; }
};

// A point on the unit box's floor, ceiling, back and side walls (no front wall), with its
// normal; 30 % of the points fall in a disc of radius 0.1 on the floor (the "caustic").
void surfacePoint(Rng& rng, glm::vec3& p, glm::vec3& n) {
  const float u = rng.uniform(), v = rng.uniform();
  const float pick = rng.uniform();
  if (pick < 0.3f) {
    const float r = 0.1f * std::sqrt(u), phi = 6.2831853f * v;
    p = {0.5f + r * std::cos(phi), 0.0f, 0.5f + r * std::sin(phi)};
    n = {0, 1, 0};
    return;
  }
  switch (static_cast<int>(rng.uniform() * 5.0f)) {
    case 0: p = {u, 0, v}; n = {0, 1, 0}; break;
    case 1: p = {u, 1, v}; n = {0, -1, 0}; break;
    case 2: p = {u, v, 1}; n = {0, 0, -1}; break;
    case 3: p = {0, u, v}; n = {1, 0, 0}; break;
    default: p = {1, u, v}; n = {-1, 0, 0}; break;
  }
}

std::vector<Photon> makePhotons(std::size_t count) {
  Rng rng{1};
  std::vector<Photon> photons(count);
  const glm::vec3 power(1.0f / static_cast<float>(count));
  for (auto& ph : photons) {
    glm::vec3 p, n;
    surfacePoint(rng, p, n);
    ph = Photon::make(p, power, n);
  }
  return photons;
}

struct Queries {
  std::vector<glm::vec3> points, normals;
};

Queries makeQueries(std::size_t count) {
  Rng rng{2};
  Queries q;
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 p, n;
    surfacePoint(rng, p, n);
    q.points.push_back(p);
    q.normals.push_back(n);
  }
  return q;
}

#ifdef PARRENDER_HAVE_NANOFLANN
// Flat xyz floats: the accessor nanoflann calls per coordinate is one indexed load (glm's
// operator[] is a switch under GLM_FORCE_XYZW_ONLY, which would slow the anchor down).
struct PointCloud {
  std::vector<float> xyz;
  std::size_t kdtree_get_point_count() const { return xyz.size() / 3; }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return xyz[3 * i + dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};
using NanoTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>, PointCloud, 3, std::uint32_t>;
#endif

}  // namespace

// Pass 1 on the bundled Cornell box (200k global + 100k caustic photons requested): photons
// emitted per second per PE at P = 1 and P = 2 in the same run, wall time of the tracing stage
// (best of repeat), and the speed-up; the lists are checked identical.
void tracingSection(int repeat) {
  const pr::scene::Scene scene = pr::scene::loadGltf(std::string(PARRENDER_SOURCE_DIR) + "/scenes/cornell.gltf");
  const pr::rt::Bvh bvh(scene);
  pr::pm::PhotonOptions options;
  std::printf("\n== photon tracing, bundled Cornell box, %zu global + %zu caustic photons requested ==\n",
              options.globalPhotons, options.causticPhotons);
  double best[2] = {1e30, 1e30};
  std::size_t emitted = 0, stored[2] = {0, 0};
  for (int p = 1; p <= 2; ++p)
    for (int r = 0; r < repeat; ++r) {
      pr::par::Runtime runtime(p);
      const auto start = Clock::now();
      const pr::pm::PhotonLists lists = pr::pm::tracePhotonLists(scene, bvh, options, runtime);
      best[p - 1] = std::min(best[p - 1], secondsSince(start));
      emitted = lists.stats.globalEmitted + lists.stats.causticEmitted;
      stored[p - 1] = lists.global.size() + lists.caustic.size();
    }
  for (int p = 1; p <= 2; ++p)
    std::printf("P = %d: %.1f ms, %.2f M photons emitted/s per PE (%zu emitted, %zu stored)\n", p, 1e3 * best[p - 1],
                double(emitted) / best[p - 1] / double(p) * 1e-6, emitted, stored[p - 1]);
  std::printf("speed-up P = 2 / P = 1: %.2f (efficiency %.2f); same photons stored: %s\n", best[0] / best[1],
              best[0] / (2.0 * best[1]), stored[0] == stored[1] ? "yes" : "NO");
}

int main(int argc, char** argv) {
  pr::retainFreedMemory();
  std::size_t photonCount = 1000000, queryCount = 200000;
  int k = 50, repeat = 3;
  float radius = 0.05f;
  CLI::App app{"bench_photonmap: photon map storage, kd-tree build and k-nearest queries (against nanoflann when built with it)"};
  app.add_option("--photons", photonCount, "photons in the map")->check(CLI::Range(std::size_t{1}, std::size_t{1} << 32))->capture_default_str();
  app.add_option("--queries", queryCount, "k-nearest queries")->check(CLI::Range(std::size_t{1}, std::size_t{1} << 32))->capture_default_str();
  app.add_option("--k", k, "neighbours per query")->check(CLI::Range(1, 100000))->capture_default_str();
  app.add_option("--radius", radius, "largest search radius")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--repeat", repeat, "passes, the best reported")->check(CLI::Range(1, 100))->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const std::vector<Photon> photons = makePhotons(photonCount);
  const Queries queries = makeQueries(queryCount);
  std::printf("bench_photonmap: %zu photons on a Cornell-like box (30 %% in a floor blob), %zu queries, k = %d, max radius %.3f, best of %d\n",
              photonCount, queryCount, k, radius, repeat);
  std::printf("\n== storage ==\n");
  std::printf("bytes per photon: %zu (position 12, RGBE power 4, octahedral direction 2, flags 1, bounces 1); the kd-tree adds none\n",
              sizeof(Photon));

  // ---- build -------------------------------------------------------------------------------
  std::printf("\n== kd-tree build, %zu photons ==\n", photonCount);
  KdTree tree;
  double serialBest = 1e30;
  for (int r = 0; r < repeat; ++r) {
    std::vector<Photon> copy = photons;
    const auto t0 = Clock::now();
    tree = KdTree::build(std::move(copy));
    serialBest = std::min(serialBest, secondsSince(t0));
  }
  std::printf("%-28s %8.1f ms\n", "serial (one thread)", 1e3 * serialBest);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<int> peCounts{2};
  if (cores > 2) peCounts.push_back(cores);
  for (int pes : peCounts) {
    pr::par::Runtime runtime(pes);
    double best = 1e30;
    bool same = true;
    for (int r = 0; r < repeat; ++r) {
      std::vector<Photon> copy = photons;
      const auto t0 = Clock::now();
      const KdTree parallel = KdTree::build(std::move(copy), runtime);
      best = std::min(best, secondsSince(t0));
      same = same && std::memcmp(parallel.photons().data(), tree.photons().data(), tree.bytes()) == 0;
    }
    char label[64];
    std::snprintf(label, sizeof label, "runtime P = %d", pes);
    std::printf("%-28s %8.1f ms   speed-up %.2f   tree %s the serial one\n", label, 1e3 * best, serialBest / best,
                same ? "bit-identical to" : "DIFFERS from");
  }

  // ---- queries -----------------------------------------------------------------------------
  std::printf("\n== k = %d nearest photons, one thread ==\n", k);
  NearestPhotons out;
  double checksum = 0.0, foundTotal = 0.0, ourBest = 1e30, ourUnboundedBest = 1e30;
  for (int r = 0; r < repeat; ++r) {
    double sum = 0.0, found = 0.0;
    const double c0 = threadCpuSeconds();
    for (std::size_t q = 0; q < queryCount; ++q) {
      tree.nearest(queries.points[q], k, radius, out);
      for (const auto& nb : out.neighbors) sum += nb.distSq;
      found += static_cast<double>(out.size());
    }
    ourBest = std::min(ourBest, threadCpuSeconds() - c0);
    checksum = sum;
    foundTotal = found;
  }
  double checksumUnbounded = 0.0;
  for (int r = 0; r < repeat; ++r) {
    double sum = 0.0;
    const double c0 = threadCpuSeconds();
    for (std::size_t q = 0; q < queryCount; ++q) {
      tree.nearest(queries.points[q], k, std::numeric_limits<float>::infinity(), out);
      for (const auto& nb : out.neighbors) sum += nb.distSq;
    }
    ourUnboundedBest = std::min(ourUnboundedBest, threadCpuSeconds() - c0);
    checksumUnbounded = sum;
  }
  const double ourQps = static_cast<double>(queryCount) / ourBest;
  const double ourUnboundedQps = static_cast<double>(queryCount) / ourUnboundedBest;
  std::printf("%-38s %10.0f queries/s  (%.2f photons found per query)\n", "parrender, max radius", ourQps,
              foundTotal / static_cast<double>(queryCount));
  std::printf("%-38s %10.0f queries/s\n", "parrender, no radius", ourUnboundedQps);
  // Read, so the timed searches cannot be optimised away.
  std::printf("%-38s %.6g (max radius), %.6g (no radius)\n", "sum of squared distances found", checksum, checksumUnbounded);

  // The full irradiance estimate (search + surface filter + density) for scale.
  {
    pr::pm::DensityOptions options;
    options.k = k;
    options.maxRadius = radius;
    double best = 1e30, sink = 0.0;
    for (int r = 0; r < repeat; ++r) {
      const double c0 = threadCpuSeconds();
      for (std::size_t q = 0; q < queryCount; ++q)
        sink += pr::pm::estimateIrradiance(tree, queries.points[q], queries.normals[q], options, out).irradiance.x;
      best = std::min(best, threadCpuSeconds() - c0);
    }
    std::printf("%-38s %10.0f estimates/s  (mean E %.3g)\n", "parrender, irradiance estimate", static_cast<double>(queryCount) / best,
                sink / static_cast<double>(repeat) / static_cast<double>(queryCount));
  }

#ifdef PARRENDER_HAVE_NANOFLANN
  PointCloud cloud;
  for (const Photon& p : photons) cloud.xyz.insert(cloud.xyz.end(), {p.position.x, p.position.y, p.position.z});
  const auto b0 = Clock::now();
  NanoTree nano(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  const double nanoBuild = secondsSince(b0);
  // nanoflann leaves the points where they are and reaches a leaf's points through its index
  // array (vAcc), a cache miss per point on 1M points; a user can put the points in leaf order
  // first (then the same tree has contiguous leaves). Both are measured; the ratio that counts
  // is against the faster.
  PointCloud leafOrder;
  leafOrder.xyz.reserve(cloud.xyz.size());
  for (std::uint32_t i : nano.vAcc) leafOrder.xyz.insert(leafOrder.xyz.end(), &cloud.xyz[3 * i], &cloud.xyz[3 * i + 3]);
  NanoTree nanoLeaf(3, leafOrder, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  std::vector<std::uint32_t> indices(static_cast<std::size_t>(k));
  std::vector<float> dists(static_cast<std::size_t>(k));
  auto runNano = [&](const NanoTree& index, float maxRadius, double& sumOut) {
    double best = 1e30;
    for (int r = 0; r < repeat; ++r) {
      double sum = 0.0;
      const double c0 = threadCpuSeconds();
      for (std::size_t q = 0; q < queryCount; ++q) {
        nanoflann::KNNResultSet<float, std::uint32_t> result(static_cast<std::size_t>(k));
        result.init(indices.data(), dists.data());
        // The same search sphere as ours: nanoflann compares dist < worstDist(), and its worst
        // distance is the last slot until the set is full.
        if (std::isfinite(maxRadius))
          dists.back() = std::nextafter(maxRadius * maxRadius, std::numeric_limits<float>::infinity());
        const float* x = &queries.points[q].x;
        index.findNeighbors(result, x, nanoflann::SearchParams());
        for (std::size_t j = 0; j < result.size(); ++j) sum += dists[j];
      }
      best = std::min(best, threadCpuSeconds() - c0);
      sumOut = sum;
    }
    return static_cast<double>(queryCount) / best;
  };
  double sums[4] = {};
  const double nanoQps = runNano(nano, radius, sums[0]);
  const double nanoUnboundedQps = runNano(nano, std::numeric_limits<float>::infinity(), sums[1]);
  const double leafQps = runNano(nanoLeaf, radius, sums[2]);
  const double leafUnboundedQps = runNano(nanoLeaf, std::numeric_limits<float>::infinity(), sums[3]);
  char nanoLabel[64];
  std::snprintf(nanoLabel, sizeof nanoLabel, "nanoflann 0x%x, max radius", static_cast<unsigned>(NANOFLANN_VERSION));
  std::printf("%-38s %10.0f queries/s\n", nanoLabel, nanoQps);
  std::printf("%-38s %10.0f queries/s\n", "nanoflann, no radius", nanoUnboundedQps);
  std::printf("%-38s %10.0f queries/s\n", "nanoflann leaf-ordered, max radius", leafQps);
  std::printf("%-38s %10.0f queries/s\n", "nanoflann leaf-ordered, no radius", leafUnboundedQps);
  const double bestNano = std::max(nanoQps, leafQps), bestNanoUnbounded = std::max(nanoUnboundedQps, leafUnboundedQps);
  std::printf("ratio parrender / nanoflann (the faster of the two): %.2fx with the max radius, %.2fx without (target >= 1.0x, goal 1.5x)\n",
              ourQps / bestNano, ourUnboundedQps / bestNanoUnbounded);
  auto same = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(a)); };
  const bool agree = same(sums[0], checksum) && same(sums[2], checksum) && same(sums[1], checksumUnbounded) &&
                     same(sums[3], checksumUnbounded);
  std::printf("same neighbours (sum of squared distances): %s (%.9g vs %.9g)\n", agree ? "yes" : "NO", checksum, sums[0]);
  std::printf("nanoflann build %.1f ms (leaf size 10, one thread), %.1f bytes per point with its 12-byte points\n",
              1e3 * nanoBuild, 12.0 + static_cast<double>(nano.usedMemory(nano)) / static_cast<double>(photonCount));
  std::printf("ratio build nanoflann / parrender serial: %.2fx\n", nanoBuild / serialBest);
#else
  std::printf("nanoflann anchor skipped: nanoflann.hpp not found at configure time (tools/setup.sh --bench installs libnanoflann-dev)\n");
#endif
  tracingSection(repeat);
  return 0;
}
