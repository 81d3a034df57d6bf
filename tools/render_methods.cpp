// The render-method registry (see render_methods.h). Ray-tracing methods come one per entry
// of the raytrace partition registry, so a new partition appears here with its registry line.
#include "tools/render_methods.h"

#include <cstdio>

#include "common/parallel/metrics.h"
#include "common/util/error.h"
#include "common/util/memory_limit.h"
#include "raster/composite/compositor.h"
#include "raster/parallel_pipeline.h"
#include "raster/stages/background.h"
#include "raster/stages/shade.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/partition/partition.h"
#include "tools/integrators.h"

namespace pr::cli {

namespace {

// "glossy, caustics" for the effects of `plan` that are on but not in `simulated`.
std::string notSimulated(const scene::RenderPlan& plan, scene::EffectSet simulated) {
  std::string out;
  for (scene::Effect e : scene::allEffects())
    if (plan.on(e) && !simulated.has(e)) out += (out.empty() ? "" : ", ") + std::string(scene::toString(e));
  return out;
}

}  // namespace

rt::TraceJob rayJobFor(const RenderRequest& r) {
  rt::TraceOptions options;
  options.integrator.effects = r.plan.enabled();
  options.integrator.spp = samplesPerPixel(r.settings.ray);
  options.integrator.maxDepth = r.settings.ray.maxDepth;
  options.integrator.seed = r.settings.ray.seed;
  options.tileSizePx = r.settings.ray.tileSizePx;
  options.adaptive = r.settings.ray.adaptive;
  options.rayBatch = r.settings.ray.rayBatch;
  options.cacheBytes = std::size_t(r.settings.ray.cacheMb * 1048576.0);
  options.dataLatencySeconds = r.settings.ray.dataLatencyUs * 1e-6;
  options.hideLatency = !r.settings.ray.noLatencyHiding;
  options.prefetch = r.settings.ray.prefetch == "none"     ? rt::TraceOptions::Prefetch::None
                     : r.settings.ray.prefetch == "camera" ? rt::TraceOptions::Prefetch::CameraRays
                                                           : rt::TraceOptions::Prefetch::Profile;
  options.progress = r.progress;
  rt::TraceJob job{r.scene, r.camera, r.width, r.height, options};
  const bool photonmap = r.settings.ray.integrator == "photonmap";
  for (const CLI::Option* o : r.settings.ray.photonOptions)
    if (o->count() > 0 && !photonmap)
      throw InputError(o->get_name() + " applies to --integrator photonmap, not " + r.settings.ray.integrator);
  pm::PhotonMapSettings photonSettings = r.settings.ray.photonmap;
  photonSettings.view = pm::parsePhotonView(r.settings.ray.view);
  job.integrator = integrators(photonSettings).find(r.settings.ray.integrator).make(
      rt::IntegratorSetup{r.scene, r.camera, r.width, r.height, options.integrator});
  return job;
}

namespace {

RenderOutcome renderRay(std::string_view name, const RenderRequest& r) {
  const rt::TraceJob job = rayJobFor(r);
  const rt::TraceOptions& options = job.options;
  const bool photonmap = r.settings.ray.integrator == "photonmap";
  const pm::PhotonView photonView = pm::parsePhotonView(r.settings.ray.view);
  rt::TraceResult result = rt::renderRays(job, name, r.runtime);
  r.runtime.gatherRecord();  // across ranks: rank 0's record becomes the whole run's
  RenderOutcome out;
  out.image = std::move(result.image);
  // The ray figures as the run record holds them (Rays/ counters, summed over PEs).
  const par::RunSummary summary = par::summarize(r.runtime.record());
  auto total = [&](const char* name) {
    for (const par::CounterSummary& c : summary.counters)
      if (c.name == name) return uint64_t(c.total);
    return uint64_t{0};
  };
  const uint64_t camera = total("Rays/camera"), continuation = total("Rays/continuation"), shadow = total("Rays/shadow");
  // The pre-pass's rays (photons, probes, gather rays) are in these counts too: the pre-pass
  // runs through the same tracer.
  out.rays = camera + continuation + shadow;
  // The work the plan skipped, from the Plan/ counters of the run record.
  std::string skipped;
  for (const par::CounterSummary& c : summary.counters)
    if (c.name.starts_with("Plan/") && c.total > 0.0)
      skipped += (skipped.empty() ? "" : ", ") + c.name.substr(5) + " " + std::to_string(uint64_t(c.total));
  const std::string missing = notSimulated(r.plan, job.integrator->simulated());
  out.effects = "integrator " + r.settings.ray.integrator + " simulates the plan's effects" +
                (missing.empty() ? "" : " except " + missing + " (not implemented by it)") +
                "; skipped work: " + (skipped.empty() ? "none" : skipped);
  out.details = "integrator " + r.settings.ray.integrator + ", spp " + std::to_string(options.integrator.spp) +
                ", max depth " + std::to_string(options.integrator.maxDepth) + "; rays: camera " +
                std::to_string(camera) + ", continuation " + std::to_string(continuation) + ", shadow " +
                std::to_string(shadow) + "; tasks " + std::to_string(result.tasks);
  if (name == "image-space-cached") {
    const uint64_t hits = total("Cache/hits"), misses = total("Cache/misses"), joined = total("Cache/misses_joined");
    const uint64_t uses = hits + misses + joined;
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%.4f", uses > 0 ? double(hits) / double(uses) : 1.0);
    out.details += "; geometry cache " + formatBytes(options.cacheBytes) + " per PE: hits " + std::to_string(hits) +
                   ", misses " + std::to_string(misses) + " requested and " + std::to_string(joined) + " joined (hit ratio " + ratio + "), prefetches " +
                   std::to_string(total("Cache/prefetches")) + ", own items used " + std::to_string(total("Cache/own_item_uses"));
  }
  if (photonmap)
    out.details += "; photons stored: global " + std::to_string(total("Photons/global_stored")) + ", caustic " +
                   std::to_string(total("Photons/caustic_stored")) + "; irradiance-cache records " +
                   std::to_string(total("IrradianceCache/records")) + " from " +
                   std::to_string(total("IrradianceCache/probes")) + " probes, gather hits " +
                   std::to_string(total("IrradianceCache/gather_hits")) +
                   (photonView != pm::PhotonView::Full ? "; view " + r.settings.ray.view : "");
  return out;
}

// The total over PEs of the named per-PE counter in the run record (0 when not recorded).
uint64_t counterTotal(const par::RunRecord& record, std::string_view name) {
  for (const par::CounterRecord& c : record.counters)
    if (c.name == name) {
      double sum = 0.0;
      for (double v : c.perPe) sum += v;
      return static_cast<uint64_t>(sum);
    }
  return 0;
}

// One sort point over --frames frames (the camera turned 2 pi i / N about the scene centre
// with --orbit); the image is the last frame's; the sort point is kept between frames. The
// summary reads the sort point's counters from the run record by name (totals over frames).
RenderOutcome renderRaster(std::string_view name, const RenderRequest& r) {
  const RasterOptions& o = r.settings.raster;
  raster::SortOptions options;
  options.regions = raster::parseRegionStrategy(o.regions);
  options.tileSizePx = o.tileSizePx;
  options.compositor = o.compositor;
  options.sparse = o.sparse;
  options.headlight = o.headlight;
  options.effects = r.plan.enabled();
  std::unique_ptr<raster::SortPoint> sortPoint = raster::makeSortPoint(name);
  raster::RegionFramebuffer last;
  for (int frame = 0; frame < o.frames; ++frame) {
    const float angle = o.orbit ? 6.28318530718f * float(frame) / float(o.frames) : 0.0f;
    const scene::Camera camera = raster::orbitCamera(r.camera, r.scene.bounds.center(), angle);
    raster::renderFrame(*sortPoint, r.scene, raster::makeFrameView(camera, r.width, r.height), options, r.runtime,
                        last);
    if (r.progress) r.progress(frame + 1, o.frames);
  }
  const par::RunRecord& record = r.runtime.gatherRecord();  // across ranks: the whole run's, on rank 0
  // The raster stages (raster/stages/shade.cpp) shade each visible pixel once: direct light
  // from punctual lights and the environment (image-based; a headlight without either) with
  // its glossy highlight, emission and textures, each skipped (and counted) when the plan has
  // it off; the environment's reflection under the plan's specular and glossy (shade.h); no
  // shadows, reflection or refraction rays.
  const bool environment = raster::showsEnvironment(r.scene, o.headlight);
  scene::EffectSet rasterEffects = scene::EffectSet::none();
  for (scene::Effect e : {scene::Effect::DirectLight, scene::Effect::Emission, scene::Effect::Textures})
    rasterEffects.set(e, true);
  rasterEffects.set(scene::Effect::IdealSpecular, environment);
  rasterEffects.set(scene::Effect::GlossySpecular, environment);
  const std::string missing = notSimulated(r.plan, rasterEffects);
  const auto count = [&](std::string_view counter) { return std::to_string(counterTotal(record, counter)); };
  RenderOutcome out;
  out.image = raster::toImage(last);
  std::string skipped;
  for (const char* c : {"Plan/texture_evaluations_skipped", "Plan/emission_skipped", "Plan/light_samples_skipped"})
    if (const uint64_t n = counterTotal(record, c); n > 0)
      skipped += (skipped.empty() ? "" : ", ") + std::string(c + 5) + " " + std::to_string(n);
  out.effects = std::string("rasterization simulates direct light (") +
                (raster::litByHeadlight(r.scene, o.headlight)
                     ? "a headlight"
                     : std::string(r.scene.lights.empty() ? "" : "punctual lights") +
                           (environment ? std::string(r.scene.lights.empty() ? "" : ", ") +
                                              "the environment by image-based lighting"
                                        : "")) +
                ", no shadows), " + (environment ? "the environment's specular and glossy reflection, " : "") +
                "emission and textures" +
                (missing.empty() ? std::string() : "; not simulated: " + missing) +
                "; skipped work: " + (skipped.empty() ? "none" : skipped);
  out.details = "frames " + std::to_string(o.frames) + (o.orbit ? " (orbit)" : "") + ", regions " + o.regions +
                ", tile " + std::to_string(o.tileSizePx) + " px";
  if (name == "sort-first")
    out.details += "; primitives routed " + count("Sort/primitives_routed") + ", sent " + count("Sort/primitives_sent") +
                   ", duplicated " + count("Sort/primitives_duplicated") + ", migrated " +
                   count("Sort/primitives_migrated") + ", pre-transforms " + count("Sort/pre_transforms") +
                   ", geometry repeated " + count("Sort/geometry_repeated");
  if (name == "sort-middle")
    out.details += "; triangles routed " + count("Sort/triangles_routed") + ", sent " + count("Sort/triangles_sent") +
                   ", duplicated " + count("Sort/triangles_duplicated");
  if (name == "sort-last")
    out.details += "; compositor " + o.compositor + (o.sparse ? " (sparse)" : " (full frame)") + ", pixels sent " +
                   count("Sort/pixels_sent") + " in " + count("Sort/composite_messages") + " messages (" +
                   count("Sort/composite_bytes") + " bytes)";
  // Image assembly: the finished regions sent to the assembler PE (channels of kind results).
  uint64_t resultMessages = 0, resultBytes = 0;
  for (const par::StageRecord& stage : record.stages)
    for (const par::ChannelTraffic& c : stage.channels)
      if (c.kind == par::toString(par::MessageKind::Results)) {
        resultMessages += c.messages;
        resultBytes += c.bytes;
      }
  out.details += "; regions to the assembler " + std::to_string(resultMessages) + " messages (" +
                 std::to_string(resultBytes) + " bytes)";
  return out;
}

bool runsAcrossRanksByName(std::string_view name) {
  if (raster::isSortPoint(name)) return raster::makeSortPoint(name)->runsAcrossRanks();
  return rt::isPartition(name) && rt::makePartition(name)->runsAcrossRanks();
}

RenderMethodRegistry makeMethods() {
  RenderMethodRegistry methods("method");
  for (const rt::PartitionInfo& p : rt::partitions())
    methods.add({p.name, p.description, renderRay, {MethodFamily::Ray, p.name == "sequential"}});
  for (const raster::SortPointInfo& s : raster::sortPoints())
    methods.add({s.name, s.description, renderRaster, {MethodFamily::Raster, s.name == "sequential-raster"}});
  return methods;
}

}  // namespace

std::string_view toString(MethodFamily family) {
  return family == MethodFamily::Ray ? "ray-tracing" : "rasterization";
}

const RenderMethodRegistry& renderMethods() {
  static const RenderMethodRegistry kMethods = makeMethods();
  return kMethods;
}

const RenderMethod& findRenderMethod(std::string_view name) { return renderMethods().find(name); }

bool isOnePeReference(std::string_view method) { return findRenderMethod(method).properties.reference; }

std::string describeRenderMethods() {
  std::string out;
  for (const RenderMethod& m : renderMethods())
    out += m.name + " (" + std::string(toString(m.properties.family)) + "): " + m.description + "\n";
  return out;
}

int samplesPerPixel(const RayOptions& ray) {
  if (ray.sppOption && ray.sppOption->count() == 0 && ray.integrator == "photonmap") return kPhotonMapDefaultSpp;
  return ray.spp;
}

void addRayOptions(CLI::App& command, RenderSettings& settings, FamilyOptions& family) {
  RayOptions& ray = settings.ray;
  family.emplace_back(command.add_option("--integrator", ray.integrator, "ray tracing: the integrator (default " + ray.integrator + "):\n" + integrators().describe())
                          ->check(CLI::Validator([](std::string& v) { return integrators().problem(v); }, "INTEGRATOR")),
                      MethodFamily::Ray);
  CLI::Option* spp = command.add_option("--spp", ray.spp,
                                     "ray tracing: stratified samples per pixel (default " + std::to_string(kDefaultSpp) + ", " +
                                         std::to_string(kPhotonMapDefaultSpp) +
                                         " for the photon map, whose fixed pre-pass fewer samples would leave noisier than it needs)")
                      ->check(CLI::Range(1, rt::kMaxSpp));
  ray.sppOption = spp;
  family.emplace_back(spp, MethodFamily::Ray);
  family.emplace_back(command.add_option("--max-depth", ray.maxDepth, "ray tracing: surface interactions shaded per path")
                          ->check(CLI::Range(1, rt::kMaxDepthLimit))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--seed", ray.seed, "ray tracing: random seed (same seed, same image)")
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--tile-size", ray.tileSizePx, "image-space: tile edge in pixels (one task per tile)")
                          ->check(CLI::Range(1, 4096))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_flag("--adaptive", ray.adaptive, "image-space: split tiles estimated at over twice the mean cost"),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--cache-mb", ray.cacheMb, "image-space-cached: each PE's LRU cache of other PEs' geometry items, in MiB (0: none, every use of a remote item fetches it)")
                          ->check(CLI::Range(0.0, 1048576.0))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--data-latency-us", ray.dataLatencyUs, "image-space-cached: simulated one-way latency of every data message, microseconds")
                          ->check(CLI::Range(0.0, 1e6))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_flag("--no-latency-hiding", ray.noLatencyHiding, "image-space-cached: a ray that needs a remote item waits for it (by default it yields to the tile's other rays)"),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--prefetch", ray.prefetch, "image-space-cached: before a tile, fetch what the PE's finished neighbouring tiles used (profile), what the tile's camera rays reach first (camera), or nothing (none)")
                          ->check(CLI::IsMember({"profile", "camera", "none"}))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--ray-batch", ray.rayBatch, "object-space, object: rays per message to one PE (a partial batch goes when its PE runs dry)")
                          ->check(CLI::Range(1, rt::kMaxRayBatch))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  // The photon map's own settings (photonmap/photon_map_integrator.h PhotonMapSettings).
  pm::PhotonMapSettings& pm = ray.photonmap;
  auto photon = [&](CLI::Option* o) {
    ray.photonOptions.push_back(o);
    family.emplace_back(o, MethodFamily::Ray);
  };
  photon(command.add_option("--photons", pm.globalPhotons, "photonmap: photons emitted for the global map")
             ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}))->capture_default_str());
  photon(command.add_option("--caustic-photons", pm.causticPhotons, "photonmap: photons emitted towards specular objects for the caustic map")
             ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}))->capture_default_str());
  photon(command.add_option("--k", pm.globalK, "photonmap: photons per global-map estimate")->check(CLI::Range(1, 10000))->capture_default_str());
  photon(command.add_option("--caustic-k", pm.causticK, "photonmap: photons per caustic-map estimate")->check(CLI::Range(1, 10000))->capture_default_str());
  photon(command.add_option("--radius", pm.globalRadius, "photonmap: global-map search radius in scene units (0 = 5% of the scene's diagonal)")
             ->check(CLI::NonNegativeNumber)->capture_default_str());
  photon(command.add_option("--caustic-radius", pm.causticRadius, "photonmap: caustic-map search radius (0 = 1.5% of the scene's diagonal)")
             ->check(CLI::NonNegativeNumber)->capture_default_str());
  photon(command.add_option("--gather", pm.gatherRays, "photonmap: final-gather rays per irradiance-cache record")
             ->check(CLI::Range(1, 65536))->capture_default_str());
  photon(command.add_option("--cache-accuracy", pm.cacheAccuracy, "photonmap: irradiance-cache accuracy a (smaller = more records)")
             ->check(CLI::Range(0.001f, 1.0f))->capture_default_str());
  photon(command.add_option("--irradiance-stride", pm.irradianceStride,
                            "photonmap: every n-th global photon carries a precomputed irradiance estimate that gathers read (0 = none: every gather hit estimates its own)")
             ->check(CLI::Range(0, 1024))->capture_default_str());
  photon(command.add_option("--view", ray.view, "photonmap: full | global-map | caustic-map (a map's estimate at the first hit)")
             ->check(CLI::IsMember({"full", "global-map", "caustic-map"}))->capture_default_str());
}

void addRasterOptions(CLI::App& command, RenderSettings& settings, FamilyOptions& family) {
  RasterOptions& r = settings.raster;
  family.emplace_back(command.add_option("--tile", r.tileSizePx, "rasterization: region tile edge in pixels")
                          ->check(CLI::Range(1, 4096))
                          ->capture_default_str(),
                      MethodFamily::Raster);
  family.emplace_back(command.add_option("--regions", r.regions, "rasterization: static-strips | static-tiles | dynamic")
                          ->check(CLI::IsMember({"static-strips", "static-tiles", "dynamic"}))
                          ->capture_default_str(),
                      MethodFamily::Raster);
  family.emplace_back(command.add_option("--compositor", r.compositor, "sort-last: the compositor (default " + r.compositor + "):\n" + raster::compositors().describe())
                          ->check(CLI::Validator([](std::string& v) { return raster::compositors().problem(v); }, "COMPOSITOR")),
                      MethodFamily::Raster);
  family.emplace_back(command.add_flag("--sparse", r.sparse, "sort-last: composite covered pixels only"), MethodFamily::Raster);
  family.emplace_back(command.add_flag("--headlight", r.headlight,
                                       "rasterization: light a scene without lights from the eye instead of by its environment"),
                      MethodFamily::Raster);
  family.emplace_back(command.add_option("--frames", r.frames, "rasterization: frames to render (the last is written)")
                          ->check(CLI::Range(1, 100000))
                          ->capture_default_str(),
                      MethodFamily::Raster);
  family.emplace_back(command.add_flag("--orbit", r.orbit, "rasterization: the camera circles the scene centre over the frames"),
                      MethodFamily::Raster);
}

// Bytes per pixel and per (pixel, sample, PE), from peak RSS of `parrender render
// scenes/cornell.gltf -m M --threads P --width 1024|2048 --spp 1|4 --max-depth 1|4` at P = 1,
// 2, 4, 8, rounded up: 64 per pixel for every method; sort-last 48 per pixel per PE; from
// P = 2, object-space about 175 per sample per PE (180 below) and object 1000 + 150 per PE
// per sample.
uint64_t estimatedRenderBytes(const RenderMethod& method, int width, int height, int pes, int spp) {
  const uint64_t pixels = uint64_t(width) * uint64_t(height), p = uint64_t(pes);
  const uint64_t samples = saturatingMul(pixels, uint64_t(method.properties.family == MethodFamily::Ray ? spp : 1));
  uint64_t bytes = saturatingMul(pixels, 64);
  auto add = [&](uint64_t more) { bytes = more > UINT64_MAX - bytes ? UINT64_MAX : bytes + more; };
  if (method.name == "sort-last") add(saturatingMul(saturatingMul(pixels, 48), p));
  if (pes > 1 && method.name == "object-space") add(saturatingMul(samples, 180 * p));
  if (pes > 1 && method.name == "object") add(saturatingMul(samples, 1000 + 150 * p));
  return bytes;
}

void checkRenderMemory(const RenderMethod& method, int width, int height, int pes, int spp) {
  std::string what = "a " + std::to_string(width) + " x " + std::to_string(height) + " render with " + method.name +
                     " at P = " + std::to_string(pes);
  if (method.properties.family == MethodFamily::Ray) what += ", " + std::to_string(spp) + " spp,";
  MemoryBudget(memoryLimit()).charge(estimatedRenderBytes(method, width, height, pes, spp), what);
}

void checkFamilyOptions(const RenderMethod& method, const FamilyOptions& family) {
  for (const auto& [option, f] : family)
    if (f != method.properties.family && option->count() > 0)
      throw InputError("option " + option->get_name() + " applies to " + std::string(toString(f)) + " methods, but '" +
                       method.name + "' is a " + std::string(toString(method.properties.family)) + " method");
}

bool runsAcrossRanks(const RenderMethod& method) { return runsAcrossRanksByName(method.name); }

std::string methodsAcrossRanks() {
  std::string names;
  for (const RenderMethod& m : renderMethods())
    if (runsAcrossRanks(m)) names += (names.empty() ? "" : ", ") + m.name;
  return names;
}

}  // namespace pr::cli
