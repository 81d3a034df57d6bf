// The hit ratio against cache size section of the report (see cache_sweep.h).
#include "tools/report/cache_sweep.h"

#include <cstdio>

#include "common/parallel/metrics.h"
#include "common/util/memory_limit.h"
#include "raster/composite/compositor.h"
#include "tools/compare/comparison_output.h"
#include "tools/report/html.h"

namespace pr::cli::report {

namespace {

constexpr const char* kMethod = "image-space-cached";

}  // namespace

std::vector<CacheRun> runCacheSweep(const ReportSpec& spec, const RenderInput& input, int threads) {
  std::vector<CacheRun> runs;
  const Placement where = everyRank(threads);
  if (where.pes < 2) return runs;
  for (double mb : spec.cacheMb) {
    if (holdsResults()) std::fprintf(stderr, "report: %s with a %g MiB cache at P = %d\n", kMethod, mb, where.pes);
    ComparisonSpec cs;
    cs.methods = {kMethod};
    cs.schedules = {spec.schedules.front()};
    cs.integrators = {"path"};
    cs.compositors = {raster::compositors().begin()->name};  // unused by a ray tracer, but must name one
    cs.threads = {threads};
    cs.oneRankBaseline = false;  // the one P of the figure
    cs.repeat = spec.repeat;
    cs.settings = spec.settings;
    cs.settings.ray.cacheMb = mb;
    cs.reference = false;
    cs.progress = false;
    runs.push_back(CacheRun{mb, runComparison(cs, input)});
  }
  return runs;
}

std::string cacheSweepSection(const ReportSpec& spec, const std::vector<CacheRun>& runs, int pes,
                              const image::Image* expected, const std::filesystem::path& dir, const std::string& relDir) {
  std::string html = "<h3>Data management: cache hit ratio against cache size</h3>";
  if (pes < 2)
    return html + "<p>Not measured: at P = 1 every data item is the PE's own, so " + std::string(kMethod) +
           " fetches nothing (give --threads a value above 1).</p>\n";
  nlohmann::json data = nlohmann::json::array();
  std::vector<std::vector<std::string>> rows;
  int differing = 0;
  for (const CacheRun& run : runs) {
    const double mb = run.cacheMb;
    const Comparison& c = run.comparison;
    if (c.rows.empty()) {
      rows.push_back({formatNumber(mb, "%.4g"), "skipped: " + (c.skipped.empty() ? std::string("-") : c.skipped.front().reason)});
      continue;
    }
    const ComparisonRow& r = c.rows.front();
    const bool same = !expected || r.image.pixels == expected->pixels;
    differing += same ? 0 : 1;
    double waiting = 0.0;
    for (const par::PeStageRecord& pe : par::peTotals(r.record)) waiting += pe.messageWaitSeconds;
    const par::KindTraffic* fetched = kindTraffic(r, "data");
    // A run that used no other PE's item has no hit ratio (the table says so, the chart leaves it out).
    if (r.cacheHitRatio >= 0.0) data.push_back({{"cacheMiB", mb}, {"hitRatio", r.cacheHitRatio}, {"wallSeconds", r.wall}});
    rows.push_back({formatNumber(mb, "%.4g"), r.cacheHitRatio >= 0.0 ? formatNumber(r.cacheHitRatio, "%.4f") : "- (no remote item used)",
                    formatNumber(counterTotal(r, "Cache/misses"), "%.0f"),
                    formatNumber(counterTotal(r, "Cache/prefetches"), "%.0f"),
                    formatBytes(fetched ? fetched->bytes : 0), formatNumber(waiting, "%.4f"), formatNumber(r.wall, "%.4f"),
                    same ? "identical" : "DIFFERS"});
  }
  html += "<p>" + std::string(kMethod) + " (image tiles on demand, the geometry split into items owned by the PEs, each PE "
          "caching other PEs' items in an LRU cache) at P = " + std::to_string(pes) + " with the " +
          escape(spec.schedules.front()) + " schedule, once per cache size (--cache-mb), each the median of " +
          std::to_string(spec.repeat) + " run" + (spec.repeat == 1 ? "" : "s") + ". A joined miss (an item already on its way) counts against the hit ratio; "
          "waiting is the PEs' time blocked on items. " +
          (differing == 0 ? std::string("Every cache size gave the comparison's image bit for bit.")
                          : "<b>" + std::to_string(differing) + " cache sizes gave an image that differs.</b>") +
          "</p>\n";
  if (!data.empty())
    html += chart(dir, relDir, "cache",
                  {{"mark", {{"type", "line"}, {"point", true}}},
                   {"encoding", {{"x", {{"field", "cacheMiB"}, {"type", "quantitative"}, {"scale", {{"type", "symlog"}}},
                                       {"axis", {{"values", spec.cacheMb}, {"format", ".6~r"}}}, {"title", "cache MiB per PE"}}},
                                 {"y", {{"field", "hitRatio"}, {"type", "quantitative"}, {"scale", {{"domain", {0, 1}}}}, {"title", "hit ratio"}}},
                                 {"tooltip", {{{"field", "cacheMiB"}}, {{"field", "hitRatio"}}, {{"field", "wallSeconds"}}}}}}},
                  data, "Cache hit ratio against cache size");
  html += table({"cache MiB", "hit ratio", "misses", "prefetches", "fetched", "waiting s", "wall s", "image"}, rows);
  return html;
}

}  // namespace pr::cli::report
