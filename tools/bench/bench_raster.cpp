// bench_raster: frame time of the raster pipelines against Mesa's llvmpipe in the same run
// (shared/ANCHORS.md). For the 1M-triangle landscape and the Cornell box: the sequential pipeline
// by stage (geometry, clear, rasterize, shade), then every sort point at P=1 and P=2 (speed-up
// and efficiency), each with Mtriangles/s, Mpixels/s and its ratio to llvmpipe drawing the same
// scene, camera and size (LP_NUM_THREADS=0 beside P=1, =1 and =2 beside P=2; one child process per
// value, since a process can use only one). Wall and CPU time, medians of --frames frames, the
// fastest of --rounds rounds in which llvmpipe and every sort point take turns. Not in ctest.
//   bench_raster [--landscape FILE] [--cornell FILE] [--width 1920] [--height 1080] [--frames 7]
//                [--rounds 3] [--anchor PATH/llvmpipe_anchor] [--no-anchor]
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/allocator.h"
#include "common/util/error.h"
#include "raster/framebuffer.h"
#include "raster/parallel_pipeline.h"
#include "raster/sequential_pipeline.h"
#include "raster/sort/sort_point.h"
#include "raster/stages/geometry.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/shade.h"

namespace {

using Clock = std::chrono::steady_clock;
namespace raster = pr::raster;

double nowMs() { return std::chrono::duration<double, std::milli>(Clock::now().time_since_epoch()).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// FNV-1a over keys and colours: equal hashes before and after a change of the stages' insides
// show the image stayed bit-identical.
uint64_t imageHash(const raster::RegionFramebuffer& fb) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  const size_t n = static_cast<size_t>(fb.rect().area());
  mix(fb.keys(), n * sizeof(uint64_t));
  mix(fb.colours(), n * sizeof(glm::vec3));
  return h;
}

// CPU time of the whole process (all PEs): on a shared machine the wall clock also counts the
// time other jobs held the cores, the CPU time does not.
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

// CPU time of the calling thread: the sequential stages run on it alone.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

// Wall and CPU milliseconds of one stage over the timed frames.
struct Span {
  std::vector<double> wall, cpu;
  void add(double wallMs, double cpuMs) {
    wall.push_back(wallMs);
    cpu.push_back(cpuMs);
  }
};

struct StageTimes {
  Span geometry, clear, raster, shade, total;
};

// One frame of the sequential pipeline over the whole screen (no regions), the stage calls of
// renderSequential with a clock around each; the image is checked against renderSequential.
void timedFrame(const pr::scene::Scene& scene, const raster::FrameView& view,
                                     raster::RegionFramebuffer& fb, StageTimes& t) {
  const double c0 = threadCpuMs(), t0 = nowMs();
  std::vector<raster::ScreenTriangle> tris;
  tris.reserve(scene.triangles.size());
  const uint32_t total = static_cast<uint32_t>(scene.triangles.size());
  constexpr uint32_t kBatch = 4096;
  for (uint32_t first = 0; first < total; first += kBatch)
    raster::processTriangles(scene, view, first, std::min(kBatch, total - first), tris);
  const double c1 = threadCpuMs(), t1 = nowMs();
  fb.clear();
  const double cc = threadCpuMs(), tc = nowMs();
  raster::rasterizeTriangles(tris, fb);
  const double c2 = threadCpuMs(), t2 = nowMs();
  raster::shadeRegion(raster::makeShadingContext(scene, view), tris, fb);
  const double c3 = threadCpuMs(), t3 = nowMs();
  t.geometry.add(t1 - t0, c1 - c0);
  t.clear.add(tc - t1, cc - c1);
  t.raster.add(t2 - tc, c2 - cc);
  t.shade.add(t3 - t2, c3 - c2);
  t.total.add(t3 - t0, c3 - c0);
}

struct Anchor {
  bool ok = false;
  double ms = 0.0, cpuMs = 0.0;
  std::string note;
};

// Runs the llvmpipe_anchor program once (its own process: LP_NUM_THREADS is fixed per process)
// and reads its JSON line.
Anchor runAnchor(const std::string& program, const std::string& scenePath, int width, int height, int threads,
                 int frames) {
  Anchor a;
  const std::string cmd = "\"" + program + "\" \"" + scenePath + "\" --width " + std::to_string(width) + " --height " +
                          std::to_string(height) + " --threads " + std::to_string(threads) + " --frames " +
                          std::to_string(frames) + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) {
    a.note = "cannot start " + program;
    return a;
  }
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int status = pclose(pipe);
  const size_t brace = out.find('{');
  if (status != 0 || brace == std::string::npos) {
    a.note = "llvmpipe_anchor failed: " + out.substr(0, 200);
    return a;
  }
  try {
    const nlohmann::json j = nlohmann::json::parse(out.substr(brace, out.find('\n', brace) - brace));
    a.ms = j.at("msPerFrameMedian").get<double>();
    a.cpuMs = j.at("cpuMsPerFrameMedian").get<double>();
    a.ok = true;
  } catch (const std::exception& e) {
    a.note = std::string("unreadable llvmpipe_anchor output: ") + e.what();
  }
  return a;
}

// One sort point on P PEs: median wall and process CPU ms per frame (the sort point is kept
// between frames, as in an animation), the image checked against the sequential reference.
struct SortRow {
  double ms = 0.0, cpuMs = 0.0;
  std::string stages;  // wall ms per frame of each stage, from the run record
};

// "name ms [busy ms of PE 0 / PE 1 ...], ..." per frame: each stage's wall time and each PE's
// busy time, summed over the timed frames (the record's stages from index `first` on).
std::string stageSummary(const pr::par::RunRecord& record, size_t first, int frames) {
  struct Sum {
    std::string name;
    double seconds = 0.0;
    std::vector<double> busy;
  };
  std::vector<Sum> sums;
  for (size_t i = first; i < record.stages.size(); ++i) {
    const pr::par::StageRecord& st = record.stages[i];
    auto at = std::find_if(sums.begin(), sums.end(), [&](const Sum& e) { return e.name == st.name; });
    if (at == sums.end()) at = sums.insert(sums.end(), Sum{st.name, 0.0, std::vector<double>(st.pes.size(), 0.0)});
    at->seconds += st.wallSeconds;
    for (size_t p = 0; p < st.pes.size() && p < at->busy.size(); ++p) at->busy[p] += st.pes[p].busySeconds;
  }
  std::string out;
  char buf[128];
  for (const Sum& sum : sums) {
    std::snprintf(buf, sizeof buf, "%s%s %.1f", out.empty() ? "" : ", ", sum.name.c_str(), 1e3 * sum.seconds / frames);
    out += buf;
    if (sum.busy.size() > 1) {
      out += " [";
      for (size_t p = 0; p < sum.busy.size(); ++p) {
        std::snprintf(buf, sizeof buf, "%s%.1f", p ? "/" : "", 1e3 * sum.busy[p] / frames);
        out += buf;
      }
      out += "]";
    }
  }
  return out;
}

SortRow timeSortPoint(const raster::SortPointInfo& info, int pes, const pr::scene::Scene& scene,
                      const raster::FrameView& view, int frames, const raster::RegionFramebuffer& reference,
                      const raster::SortOptions& options, const std::string& schedule) {
  pr::par::Runtime runtime(pes, schedule);
  std::unique_ptr<raster::SortPoint> sortPoint = info.make();
  raster::RegionFramebuffer image;
  raster::renderFrame(*sortPoint, scene, view, options, runtime, image);  // warm-up
  PR_CHECK(raster::identical(image, reference), "bench_raster: parallel image differs from the sequential one");
  const size_t firstTimedStage = runtime.record().stages.size();
  std::vector<double> wall, cpu;
  for (int f = 0; f < frames; ++f) {
    const double c0 = processCpuMs(), t0 = nowMs();
    raster::renderFrame(*sortPoint, scene, view, options, runtime, image);
    wall.push_back(nowMs() - t0);
    cpu.push_back(processCpuMs() - c0);
  }
  return SortRow{median(wall), median(cpu), stageSummary(runtime.record(), firstTimedStage, frames)};
}

struct Options {
  int width = 1920, height = 1080, frames = 7, rounds = 3;
  std::string anchor;
  bool noAnchor = false;
};

void benchScene(const std::string& label, const std::string& path, const Options& o) {
  if (!std::filesystem::exists(path)) {
    std::printf("%s: %s not found, skipped (generate it: parrender generate landscape -o FILE)\n", label.c_str(),
                path.c_str());
    return;
  }
  const pr::scene::Scene scene = pr::scene::loadGltf(path);
  const pr::scene::Camera camera = pr::scene::selectCamera(scene, "", float(o.width) / float(o.height));
  const raster::FrameView view = raster::makeFrameView(camera, o.width, o.height);
  const double triangles = double(scene.triangles.size()), pixels = double(o.width) * o.height;
  std::printf("\n== %s: %s, %zu triangles, %dx%d, median of %d frames (after one warm-up), fastest of %d rounds\n",
              label.c_str(), path.c_str(), scene.triangles.size(), o.width, o.height, o.frames, o.rounds);

  raster::RegionFramebuffer fb(raster::Rect{0, 0, o.width, o.height});
  StageTimes t;
  timedFrame(scene, view, fb, t);  // warm-up: first touch of the framebuffer and the scene
  t = {};
  for (int f = 0; f < o.frames; ++f) timedFrame(scene, view, fb, t);
  const raster::RegionFramebuffer reference = raster::renderSequential(scene, view);
  PR_CHECK(raster::identical(fb, reference), "bench_raster: timed stages differ from renderSequential");

  const double ms = median(t.total.wall), cpuMs = median(t.total.cpu);
  std::printf("sequential P=1 wall: geometry %.1f ms, clear %.1f ms, raster %.1f ms, shade %.1f ms | total %.1f ms\n",
              median(t.geometry.wall), median(t.clear.wall), median(t.raster.wall), median(t.shade.wall), ms);
  std::printf("sequential P=1 cpu:  geometry %.1f ms, clear %.1f ms, raster %.1f ms, shade %.1f ms | total %.1f ms\n",
              median(t.geometry.cpu), median(t.clear.cpu), median(t.raster.cpu), median(t.shade.cpu), cpuMs);
  const double covered = double(std::max<size_t>(1, fb.coveredPixels()));
  std::printf("sequential P=1: %.2f Mtriangles/s, %.1f Mpixels/s (per cpu second: %.2f, %.1f), %zu covered pixels, "
              "shade %.1f cpu ns/covered pixel\n",
              triangles / ms / 1e3, pixels / ms / 1e3, triangles / cpuMs / 1e3, pixels / cpuMs / 1e3,
              fb.coveredPixels(), 1e6 * median(t.shade.cpu) / covered);
  std::printf("image hash %016llx\n", static_cast<unsigned long long>(imageHash(fb)));
  // llvmpipe first, so every row below can print its ratio. LP_NUM_THREADS=0 draws on one
  // thread, the counterpart of P=1. Beside P=2 stand both =1 (front end + one tile thread: two
  // threads, like P=2) and =2 (front end + two tile threads); the faster is the bar.
  Anchor anchors[3];
  const bool anchorRuns = !o.noAnchor && !o.anchor.empty() && std::filesystem::exists(o.anchor);
  if (o.noAnchor) std::printf("llvmpipe: skipped (--no-anchor)\n");
  else if (!anchorRuns) std::printf("llvmpipe: anchor program not available (build the llvmpipe_anchor target), no ratios\n");

  struct Variant {
    const raster::SortPointInfo* info = nullptr;
    std::string label;
    raster::SortOptions options;
    std::string schedule = "demand";
  };
  std::vector<Variant> variants;
  auto add = [&variants](const raster::SortPointInfo& info, std::string label, bool sparse, std::string schedule) {
    Variant v;
    v.info = &info;
    v.label = std::move(label);
    v.options.sparse = sparse;
    v.schedule = std::move(schedule);
    variants.push_back(std::move(v));
  };
  for (const raster::SortPointInfo& info : raster::sortPoints()) {
    if (info.name == "sequential-raster") continue;  // the sequential pipeline, timed above by stage
    add(info, std::string(info.name), false, "demand");
    if (info.name == "sort-last") {
      // Sparse compositing (bounding rectangles), with geometry batches on demand, in equal
      // contiguous portions (each PE's primitives then cover a part of the screen), and from
      // contiguous portions with a PE that finishes its own helping the other (preferred bias:
      // mostly the same locality, the balance of demand).
      add(info, "sort-last --sparse", true, "demand");
      add(info, "sort-last --sparse --schedule balanced", true, "balanced");
      add(info, "sort-last --sparse --schedule preferred-bias", true, "preferred-bias");
    }
  }
  // Rounds: every measurement once per round, llvmpipe's and ours taking turns, so that a slow
  // spell of the shared machine does not fall on one side only; each keeps its fastest round.
  std::vector<SortRow> p1s(variants.size()), p2s(variants.size());
  for (int round = 0; round < o.rounds; ++round) {
    if (anchorRuns)
      for (int threads : {0, 1, 2}) {
        const Anchor a = runAnchor(o.anchor, path, o.width, o.height, threads, o.frames);
        Anchor& best = anchors[threads];
        if (round == 0 || (a.ok && (!best.ok || a.ms < best.ms))) best = a;
      }
    for (size_t i = 0; i < variants.size(); ++i) {
      const Variant& v = variants[i];
      const SortRow p1 = timeSortPoint(*v.info, 1, scene, view, o.frames, reference, v.options, v.schedule);
      const SortRow p2 = timeSortPoint(*v.info, 2, scene, view, o.frames, reference, v.options, v.schedule);
      if (round == 0 || p1.ms < p1s[i].ms) p1s[i] = p1;
      if (round == 0 || p2.ms < p2s[i].ms) p2s[i] = p2;
    }
  }
  if (anchorRuns)
    for (int threads : {0, 1, 2}) {
      const Anchor& a = anchors[threads];
      if (a.ok) std::printf("llvmpipe LP_NUM_THREADS=%d: %.1f ms (cpu %.1f ms)\n", threads, a.ms, a.cpuMs);
      else std::printf("llvmpipe LP_NUM_THREADS=%d: %s\n", threads, a.note.c_str());
    }
  auto ratio = [&anchors](int threads, double ourMs, double ourCpuMs) {
    const Anchor& a = anchors[threads];
    if (!a.ok) return std::string();
    char buf[96];
    std::snprintf(buf, sizeof buf, " | / llvmpipe LP_NUM_THREADS=%d: %.2f (cpu %.2f)", threads, ourMs / a.ms,
                  ourCpuMs / a.cpuMs);
    return std::string(buf);
  };
  std::printf("sequential P=1: %.1f ms (cpu %.1f ms)%s\n", ms, cpuMs, ratio(0, ms, cpuMs).c_str());

  for (size_t i = 0; i < variants.size(); ++i) {
    const Variant& v = variants[i];
    const raster::SortPointInfo& info = *v.info;
    const SortRow& p1 = p1s[i];
    const SortRow& p2 = p2s[i];
    const std::string p2Ratios = ratio(1, p2.ms, p2.cpuMs) + ratio(2, p2.ms, p2.cpuMs);
    std::printf("%s P=1: %.1f ms (cpu %.1f ms), %.2f Mtriangles/s, %.1f Mpixels/s%s\n", v.label.c_str(),
                p1.ms, p1.cpuMs, triangles / p1.ms / 1e3, pixels / p1.ms / 1e3, ratio(0, p1.ms, p1.cpuMs).c_str());
    std::printf("%s P=2: %.1f ms (cpu %.1f ms), %.2f Mtriangles/s, %.1f Mpixels/s, speed-up T1/T2 %.2f, efficiency "
                "%.2f%s\n",
                v.label.c_str(), p2.ms, p2.cpuMs, triangles / p2.ms / 1e3, pixels / p2.ms / 1e3,
                p1.ms / p2.ms, p1.ms / (2.0 * p2.ms), p2Ratios.c_str());
    std::printf("  %s stages, ms per frame, P=1: %s\n", v.label.c_str(), p1.stages.c_str());
    std::printf("  %s stages, ms per frame, P=2: %s\n", v.label.c_str(), p2.stages.c_str());
    if (info.name == "sort-last" && v.options.sparse)
      std::printf("%s P=2 efficiency %.2f (target >= 0.8 on the landscape)\n", v.label.c_str(), p1.ms / (2.0 * p2.ms));
    if (info.name == "sort-middle" && (anchors[1].ok || anchors[2].ok)) {
      const double best = std::min(anchors[1].ok ? anchors[1].ms : 1e300, anchors[2].ok ? anchors[2].ms : 1e300);
      std::printf("sort-middle P=2 / fastest llvmpipe on two cores: %.2f (bar 1.5, goal 1.0)\n", p2.ms / best);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  pr::retainFreedMemory();
  CLI::App app{"bench_raster: raster pipeline frame times against Mesa llvmpipe in the same run"};
  Options o;
  std::string landscape = PARRENDER_BINARY_DIR "/scenes/landscape.glb";
  std::string cornell = PARRENDER_SOURCE_DIR "/scenes/cornell.gltf";
#ifdef PARRENDER_LLVMPIPE_ANCHOR_EXE
  o.anchor = PARRENDER_LLVMPIPE_ANCHOR_EXE;
#endif
  app.add_option("--landscape", landscape, "large scene (parrender generate landscape -o FILE)")->capture_default_str();
  app.add_option("--cornell", cornell, "fill-bound scene")->capture_default_str();
  app.add_option("--width", o.width, "image width")->check(CLI::Range(1, raster::kMaxImageSidePx))->capture_default_str();
  app.add_option("--height", o.height, "image height")->check(CLI::Range(1, raster::kMaxImageSidePx))
      ->capture_default_str();
  app.add_option("--frames", o.frames, "timed frames per measurement")->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--rounds", o.rounds,
                 "rounds of every measurement (llvmpipe and each sort point at P = 1 and 2 taking turns); each row "
                 "reports its fastest round's median")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--anchor", o.anchor, "llvmpipe_anchor program")->capture_default_str();
  app.add_flag("--no-anchor", o.noAnchor, "skip llvmpipe");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : pr::kExitBadInput;
  }
  try {
    benchScene("landscape", landscape, o);
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("peak memory after the landscape (ru_maxrss): %.1f MiB\n", double(usage.ru_maxrss) / 1024.0);
    benchScene("cornell", cornell, o);
  } catch (const pr::InputError& e) {
    std::fprintf(stderr, "bench_raster: error: %s\n", e.what());
    return pr::kExitBadInput;
  }
  return 0;
}
