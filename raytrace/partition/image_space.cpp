// Image-space partitioning (seed section 5.1.2): the image is cut into tiles, each tile is a
// task on par::Runtime, and every scheduling strategy of the runtime decides which PE renders
// which tile. World model: every PE reads the whole scene and its BVH, counted as one
// broadcast of the scene's and the BVH's bytes per PE; finished tiles travel to the assembler. Cost estimates, for the strategies that declare they
// need them in the schedule registry (par::scheduleNeedsCostEstimates: unbalanced, hot-spots),
// come from a cheap low-resolution pre-pass; --adaptive splits expensive tiles.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/wire.h"
#include "raytrace/partition/film_assembly.h"
#include "raytrace/partition/partition.h"
#include "raytrace/partition/partitioned.h"
#include "raytrace/partition/tile_trace.h"

namespace pr::rt {

namespace {

// Adaptive subdivision: a tile estimated at more than this many times the mean tile cost is
// split into four, so no single task dominates the end of the stage.
constexpr double kAdaptiveSplitFactor = 2.0;

struct TileTask {
  PixelRect rect;
  float x = 0.0f, y = 0.0f;  // centre in tile units (spiral order, reports)
  double cost = 1.0;
};

class ImageSpacePartition final : public Partition {
 public:
  std::string_view name() const override { return "image-space"; }
  bool holdsWorldModel() const override { return true; }
  bool runsAcrossRanks() const override { return true; }

  TraceResult render(const TraceJob& job, par::Runtime& rt) override {
    // The world BVH is built once, on the assembler's PE in a stage of its own (so its time is
    // in the record like the partitioned tracers' builds), and replicated: the scene and the
    // BVH are one broadcast per PE (world model, DESIGN.md rule 1). Across ranks every rank
    // builds it on its first PE from the scene it loaded itself (a replicated computation, one
    // task per rank): sending rank 0's instead cost more (the landscape's 86 MB BVH, 2 ranks
    // on the 2-core machine: two builds side by side 0.65-0.82 s, build, encode, send and
    // decode 0.97 s), and builds on R nodes take the same time at any R, where a broadcast
    // grows with R. The scene and BVH are booked as a broadcast to each rank's other PEs and as
    // a replicated copy on each other rank (Runtime::recordReplicated), which one process books
    // as a broadcast. A BVH handed in by the caller (TraceOptions::worldBvh) is not rebuilt:
    // its build is then outside the record.
    std::unique_ptr<Bvh> built;
    if (!job.options.worldBvh)
      rt.runOncePerRank(job.stage("build"), [&](par::Pe&) { built = std::make_unique<Bvh>(job.scene, job.options.bvh); });
    const Bvh& bvh = job.options.worldBvh ? *job.options.worldBvh : *built;
    const std::shared_ptr<const Integrator> shared = jobIntegrator(job);
    const Integrator& integrator = *shared;
    std::vector<TileTask> tiles = makeTiles(job);
    if (!job.sceneResident) rt.recordReplicated(job.scene.memoryBytes() + bvh.stats().memoryBytes);
    // A pre-pass program gets no cost pre-pass: it would run the program's side effects twice.
    if (job.assembleImage && (par::scheduleNeedsCostEstimates(rt.options().schedule) || job.options.adaptive))
      estimateCosts(job, integrator, bvh, tiles, rt);
    if (job.options.adaptive) tiles = subdivide(tiles);

    par::TaskSet set;
    set.tasks.reserve(tiles.size());
    for (const TileTask& t : tiles) set.tasks.push_back({t.cost, t.x, t.y});

    // Each tile is rendered into its own film and sent, finished, to the assembler.
    Film film(job.filmWidth(), job.filmHeight(), integrator.options().spp);
    FilmAssembly assembly(rt, film);
    PerPeTraceStats counters(rt.pes());
    std::atomic<int64_t> done{0};
    const int64_t total = int64_t(tiles.size());
    rt.runStage(job.stage("trace"), set, [&](par::Pe& pe, par::TaskId id) {
      const PixelRect& rect = tiles[size_t(id)].rect;
      TraceStats stats;
      const Film tile = traceTile(integrator, bvh, rect, job.width, job.height, pe.id(), stats);
      if (job.assembleImage) assembly.deliver(pe, tile, rect, false);
      counters.of(pe.id()) += stats;
      const int64_t n = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (job.options.progress) job.options.progress(n, total);
    });
    return TraceResult{film.toImage(), recordRayCounters(rt, counters.values()), tiles.size()};
  }

 private:
  static std::vector<TileTask> makeTiles(const TraceJob& job) {
    const int ts = job.options.tileSizePx;
    std::vector<TileTask> tiles;
    for (const PixelRect& r : tilesOf(PixelRect{0, 0, job.width, job.height}, ts))
      tiles.push_back({r, float(r.x0 / ts) + 0.5f, float(r.y0 / ts) + 0.5f, 1.0});
    return tiles;
  }

  // Low-resolution pre-pass, its own stage ("cost pre-pass", one task per tile, balanced split)
  // so its time is measured with the render: rays traced per sampled pixel, scaled to the
  // tile's pixel count. Each task writes only its tile's estimate; the scratch film is thrown away.
  // The render's integrator makes the rays, one sample per pixel (sample 0, as in a 1-spp render).
  // Across ranks each rank holds its own PEs' estimates until they are summed.
  static void estimateCosts(const TraceJob& job, const Integrator& integrator, const Bvh& bvh,
                            std::vector<TileTask>& tiles, par::Runtime& rt) {
    Film scratch(job.width, job.height, 1);
    const std::unique_ptr<par::Scheduler> balanced = par::makeScheduler("balanced");
    std::vector<double> costs(tiles.size(), 0.0);
    rt.runStage("cost pre-pass", par::TaskSet::uniform(tiles.size()), *balanced, [&](par::Pe&, par::TaskId id) {
      const TileTask& t = tiles[size_t(id)];
      std::vector<RayMessage> queue;
      TraceStats stats;
      int64_t sampled = 0;
      for (int y = t.rect.y0; y < t.rect.y1; y += kCostPrePassStride)
        for (int x = t.rect.x0; x < t.rect.x1; x += kCostPrePassStride) {
          integrator.cameraRays(PixelRect{x, y, x + 1, y + 1}, 1, queue);
          integrator.traceToCompletion(bvh, queue, scratch, stats, 0);
          ++sampled;
        }
      costs[size_t(id)] = tileCostEstimate(stats.total(), t.rect, sampled);
    });
    rt.sumAcrossRanks(costs);
    for (size_t i = 0; i < tiles.size(); ++i) tiles[i].cost = costs[i];
  }

  // Splits each tile costing more than kAdaptiveSplitFactor x the mean into four quarters
  // (each keeps a quarter of the cost estimate); tiles of one pixel stay whole.
  static std::vector<TileTask> subdivide(const std::vector<TileTask>& tiles) {
    double sum = 0.0;
    for (const TileTask& t : tiles) sum += t.cost;
    const double mean = tiles.empty() ? 0.0 : sum / double(tiles.size());
    std::vector<TileTask> out;
    for (const TileTask& t : tiles) {
      const PixelRect& r = t.rect;
      const int mx = (r.x0 + r.x1) / 2, my = (r.y0 + r.y1) / 2;
      if (t.cost <= kAdaptiveSplitFactor * mean || r.pixels() <= 1) {
        out.push_back(t);
        continue;
      }
      const PixelRect quarters[4] = {{r.x0, r.y0, mx, my}, {mx, r.y0, r.x1, my}, {r.x0, my, mx, r.y1}, {mx, my, r.x1, r.y1}};
      const float qx[4] = {-0.25f, 0.25f, -0.25f, 0.25f}, qy[4] = {-0.25f, -0.25f, 0.25f, 0.25f};
      for (int q = 0; q < 4; ++q)
        if (quarters[q].pixels() > 0) out.push_back({quarters[q], t.x + qx[q], t.y + qy[q], t.cost / 4.0});
    }
    return out;
  }
};

}  // namespace

std::unique_ptr<Partition> makeImageSpacePartition() { return std::make_unique<ImageSpacePartition>(); }

}  // namespace pr::rt
