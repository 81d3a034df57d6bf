// The comparison run (see comparison.h).
#include "tools/compare/comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numeric>
#include <set>
#include <thread>
#include <tuple>

#include "common/parallel/process_group.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/util/error.h"
#include "raster/composite/compositor.h"
#include "tools/integrators.h"
#include "tools/sweep/image_error.h"

namespace pr::cli {

std::string Combination::methodName() const { return farm.empty() ? method : method + " farm"; }

std::string Combination::label() const {
  std::string out = method + (farm.empty() ? "" : " farm(" + farm + ")") + " " + schedule;
  if (integrator != kNotApplicable) out += " " + integrator;
  if (compositor != kNotApplicable) out += " " + compositor;
  out += " P=" + std::to_string(pes);
  return ranks > 1 ? out + " R=" + std::to_string(ranks) : out;
}

const std::vector<std::string>& comparisonKinds() {
  static const std::vector<std::string> kKinds = {"tasks", "primitives", "rays", "pixels", "broadcasts", "results",
                                                  "requests", "data"};
  return kKinds;
}

const par::KindTraffic* kindTraffic(const ComparisonRow& row, const std::string& kind) {
  for (const par::KindTraffic& k : row.summary.total.byKind)
    if (k.kind == kind) return &k;
  return nullptr;
}

par::KindTraffic allTraffic(const ComparisonRow& row) {
  par::KindTraffic all{"all"};
  for (const par::KindTraffic& k : row.summary.total.byKind) {
    all.messages += k.messages, all.bytes += k.bytes;
    all.betweenRankMessages += k.betweenRankMessages, all.betweenRankBytes += k.betweenRankBytes;
  }
  return all;
}

double counterTotal(const ComparisonRow& row, const std::string& name) {
  for (const par::CounterSummary& c : row.summary.counters)
    if (c.name == name) return c.total;
  return 0.0;
}

std::vector<int> defaultThreadCounts() {
  if (par::ProcessGroup::get().ranks() > 1) return {1};
  const int cores = std::max(1, int(std::thread::hardware_concurrency()));
  std::vector<int> out;
  for (int p = 1; p < cores; p *= 2) out.push_back(p);
  out.push_back(cores);
  return out;
}

namespace {

// The list without repeats, in its order.
template <typename T>
std::vector<T> distinct(const std::vector<T>& values) {
  std::vector<T> out;
  for (const T& v : values)
    if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(v);
  return out;
}

// The render settings of one combination.
RenderSettings settingsFor(const Combination& c, const ComparisonSpec& spec) {
  RenderSettings settings = spec.settings;
  if (c.integrator != kNotApplicable) settings.ray.integrator = c.integrator;
  if (c.compositor != kNotApplicable) settings.raster.compositor = c.compositor;
  return settings;
}

// A fault for tests (PARRENDER_IMAGE_FAULT=METHOD): every image of METHOD the comparison renders
// has its first pixel changed, so that the path of an image that differs from its family's can
// be tested (compare and report exit 1, the report's verdict leaves the row out).
void injectImageFault(const Combination& c, TimedRender& t) {
  const char* method = std::getenv("PARRENDER_IMAGE_FAULT");
  if (method && c.method == method && !t.outcome.image.empty()) t.outcome.image.pixels[0] += glm::vec3(1.0f);
}

// One timed render of the combination, on every rank that takes part.
TimedRender timed(const Combination& c, const ComparisonSpec& spec, const RenderInput& input) {
  const RenderSettings settings = settingsFor(c, spec);
  const par::ScheduleOptions schedule{c.schedule, spec.scheduleParams};
  TimedRender t = !c.farm.empty() ? timedFarmRender(spec.farm, input, settings, c.pesPerProcess(), schedule)
                                  : timedRender(findRenderMethod(c.method), input, settings, Placement{c.pes, c.ranks}, schedule);
  injectImageFault(c, t);
  return t;
}

bool isPowerOfTwo(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Why the combination cannot run, or empty.
std::string whyInvalid(const Combination& c, const ComparisonSpec& spec) {
  const bool reference = isOnePeReference(c.method);
  if (reference && c.pes > 1) return c.method + " is the one-PE reference; it runs at P = 1 only";
  if (reference && c.schedule != spec.schedules.front())
    return c.method + " runs one task on one PE: every schedule gives the run measured under " + spec.schedules.front();
  if (c.compositor == "binary-swap" && !isPowerOfTwo(c.pes)) return "binary-swap needs P a power of two";
  if (c.ranks > 1 && !runsAcrossRanks(findRenderMethod(c.method)))
    return c.method + " does not run across processes; it ran on rank 0 alone";
  return {};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The share of a data manager's cache uses that hit, from the Cache/ counters; < 0 when none.
double cacheHitRatio(const par::RunSummary& summary) {
  double hits = -1.0, uses = 0.0;
  for (const par::CounterSummary& c : summary.counters) {
    if (c.name == "Cache/hits") hits = c.total, uses += c.total;
    if (c.name == "Cache/misses" || c.name == "Cache/misses_joined") uses += c.total;
  }
  return hits < 0.0 ? -1.0 : uses > 0.0 ? hits / uses : 1.0;
}

void checkNames(const std::vector<std::string>& names, const char* option, const auto& registry) {
  if (names.empty()) throw InputError(std::string(option) + ": give at least one value");
  for (const std::string& n : names)
    if (std::string problem = registry.problem(n); !problem.empty()) throw InputError(std::string(option) + ": " + problem);
}

}  // namespace

Comparison runComparison(const ComparisonSpec& given, const RenderInput& input) {
  ComparisonSpec spec = given;
  spec.methods = distinct(spec.methods);
  spec.schedules = distinct(spec.schedules);
  spec.integrators = distinct(spec.integrators);
  spec.compositors = distinct(spec.compositors);
  checkNames(spec.methods, "--methods", renderMethods());
  checkNames(spec.schedules, "--schedules", par::schedules());
  checkNames(spec.integrators, "--integrators", integrators());
  checkNames(spec.compositors, "--compositors", raster::compositors());
  if (spec.threads.empty()) throw InputError("--threads: give at least one value");
  if (spec.repeat < 1) throw InputError("--repeat: at least one run per combination");

  // The combinations, in table order: method, integrator, compositor, schedule, P. Under
  // mpirun: P = 1 on rank 0 alone first, then R x T across every rank for each T.
  const int ranks = par::ProcessGroup::get().ranks();
  std::vector<Placement> placements;
  std::vector<int> threads = spec.threads;
  std::sort(threads.begin(), threads.end());
  threads.erase(std::unique(threads.begin(), threads.end()), threads.end());
  if (ranks > 1 && spec.oneRankBaseline) placements.push_back(Placement{1, 1});
  for (int t : threads) placements.push_back(everyRank(t));
  std::vector<Combination> combinations;
  Comparison out;
  for (const std::string& name : spec.methods) {
    const RenderMethod& method = findRenderMethod(name);
    const bool ray = method.properties.family == MethodFamily::Ray;
    const std::vector<std::string> integratorList = ray ? spec.integrators : std::vector<std::string>{kNotApplicable};
    const std::vector<std::string> compositorList =
        name == "sort-last" ? spec.compositors : std::vector<std::string>{kNotApplicable};
    for (const std::string& integrator : integratorList)
      for (const std::string& compositor : compositorList)
        for (const std::string& schedule : spec.schedules)
          for (const Placement where : placements) {
            Combination c{name, method.properties.family, schedule, integrator, compositor, where.pes, where.ranks, {}};
            std::string reason = whyInvalid(c, spec);
            if (reason.empty()) {
              try {
                RayOptions rayOptions = spec.settings.ray;
                if (integrator != kNotApplicable) rayOptions.integrator = integrator;
                checkRenderMemory(method, input.width, input.height, where.pes / where.ranks, samplesPerPixel(rayOptions));
              } catch (const InputError& e) {
                reason = e.what();
              }
            }
            if (reason.empty()) combinations.push_back(c);
            else out.skipped.push_back({c.label(), reason});
          }
  }
  // The farm's combinations last: a lost server would leave the renders after it without a rank.
  if (spec.farm.enabled) {
    const RenderMethod& imageSpace = findRenderMethod("image-space");
    checkFarm(spec.farm, imageSpace, spec.settings, ranks);
    for (const std::string& integrator : spec.integrators)
      for (const std::string& schedule : spec.schedules)
        for (int t : threads) {
          const Combination c{imageSpace.name, MethodFamily::Ray, schedule, integrator, kNotApplicable, (ranks - 1) * t, ranks,
                              spec.farm.schedule};
          RayOptions rayOptions = spec.settings.ray;
          rayOptions.integrator = integrator;
          try {
            checkRenderMemory(imageSpace, input.width, input.height, t, samplesPerPixel(rayOptions));
            combinations.push_back(c);
          } catch (const InputError& e) {
            out.skipped.push_back({c.label(), e.what()});
          }
        }
  }
  for (const std::string& note : spec.notes) out.skipped.push_back({"option", note});

  if (spec.reference) out.reference = pathReference(spec.referenceSettings, input);

  // One untimed render per family first: the first render of a process pays one-time costs
  // (lazily built tables such as the environment's, first-touch page faults, the allocator's
  // growth) that would otherwise land on whichever combination happens to run first.
  // Under mpirun, once on rank 0 alone and once across ranks.
  const bool holds = holdsResults();
  const bool progress = spec.progress && holds;
  // The farm's warm-up waits for its first row, after every other render.
  std::set<std::tuple<MethodFamily, int, bool>> warmed;
  const auto warmUp = [&](const Combination& c) {
    if (!warmed.insert({c.family, c.ranks, !c.farm.empty()}).second) return;
    if (progress) std::fprintf(stderr, "warm-up (untimed): %s\n", c.label().c_str());
    (void)timed(c, spec, input);
  };
  for (const Combination& c : combinations)
    if (c.farm.empty()) warmUp(c);

  const int total = int(combinations.size()) * spec.repeat;
  int done = 0;
  // The first image of each family and integrator: every other must equal it bit for bit.
  std::map<std::pair<MethodFamily, std::string>, std::size_t> familyFirst;
  for (const Combination& c : combinations) {
    if (!c.farm.empty()) warmUp(c);
    ComparisonRow row;
    row.what = c;
    std::vector<TimedRender> runs;
    for (int r = 0; r < spec.repeat; ++r) {
      TimedRender t = timed(c, spec, input);
      ++done;
      if (!holds) continue;  // rank 0 holds the figures and images
      if (progress)
        std::fprintf(stderr, "[%d/%d] %s run %d/%d: %.3f s\n", done, total, c.label().c_str(), r + 1, spec.repeat,
                     t.wallSeconds);
      // Every repeat renders the same image (the renders are deterministic).
      if (!runs.empty())
        if (std::string d = bitDifference(t.outcome.image, runs.front().outcome.image); !d.empty()) {
          row.agrees = false;
          row.agreement = "run " + std::to_string(r + 1) + " differs from run 1: " + d;
        }
      row.wallSeconds.push_back(t.wallSeconds);
      row.cpuSeconds.push_back(t.cpuSeconds);
      runs.push_back(std::move(t));
    }
    if (!holds) continue;
    row.wall = median(row.wallSeconds);
    row.wallMin = *std::min_element(row.wallSeconds.begin(), row.wallSeconds.end());
    row.wallMax = *std::max_element(row.wallSeconds.begin(), row.wallSeconds.end());
    row.cpu = median(row.cpuSeconds);
    // The run whose wall time is the median (the lower middle for an even count).
    std::vector<std::size_t> order(runs.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return runs[a].wallSeconds < runs[b].wallSeconds; });
    TimedRender& mid = runs[order[(order.size() - 1) / 2]];
    row.record = std::move(mid.record);
    row.summary = par::summarize(row.record);
    row.cacheHitRatio = cacheHitRatio(row.summary);
    row.rays = mid.outcome.rays;
    row.effects = mid.outcome.effects;
    if (!out.reference.image.empty()) row.rmse = imageError(mid.outcome.image, out.reference.image).rmse;
    row.image = std::move(mid.outcome.image);

    const auto key = std::make_pair(c.family, c.integrator);
    if (auto first = familyFirst.find(key); first == familyFirst.end()) {
      familyFirst[key] = out.rows.size();
      if (row.agrees) row.agreement = "reference";
    } else if (row.agrees) {
      const ComparisonRow& ref = out.rows[first->second];
      const std::string d = bitDifference(row.image, ref.image);
      row.agrees = d.empty();
      row.agreement = d.empty() ? "identical" : "differs from " + ref.what.label() + ": " + d;
    }
    if (!row.agrees) {
      ++out.mismatches;
      std::fprintf(stderr, "IMAGE MISMATCH: %s %s\n", c.label().c_str(), row.agreement.c_str());
    }
    out.rows.push_back(std::move(row));
  }

  // Speed-ups: T1 is the same combination at P = 1 (a farm's: image-space's with the schedule
  // of its servers' PEs); Ts the family's serial reference for the integrator, its one-PE
  // reference method when it ran (the sequential tracer, the sequential raster pipeline),
  // else the family's fastest run at P = 1.
  for (ComparisonRow& row : out.rows) {
    const ComparisonRow* one = nullptr;
    const ComparisonRow* serial = nullptr;
    for (const ComparisonRow& other : out.rows) {
      const Combination& o = other.what;
      // A farm at P = 1 (one server) is no one-PE baseline: a master runs beside it.
      if (o.pes != 1 || !o.farm.empty() || o.family != row.what.family || o.integrator != row.what.integrator) continue;
      if (o.method == row.what.method && o.schedule == row.what.schedule && o.compositor == row.what.compositor) one = &other;
      const bool reference = isOnePeReference(o.method);
      const bool serialIsReference = serial && isOnePeReference(serial->what.method);
      if (!serial || (reference && !serialIsReference) || (reference == serialIsReference && other.wall < serial->wall))
        serial = &other;
    }
    if (one && row.wall > 0.0) {
      row.speedup = one->wall / row.wall;
      row.efficiency = row.speedup / row.what.pes;
    }
    if (serial && row.wall > 0.0) {
      row.speedupSerial = serial->wall / row.wall;
      row.serialReference = serial->what.label();
    }
  }
  if (!spec.keepImages)
    for (ComparisonRow& row : out.rows) row.image = {};
  return out;
}

}  // namespace pr::cli
