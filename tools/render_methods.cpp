// The render-method registry (see render_methods.h). Ray-tracing methods come one per entry
// of the raytrace partition registry, so a new partition appears here with its registry line.
#include "tools/render_methods.h"

#include "common/util/error.h"
#include "raster/parallel_pipeline.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/partition/partition.h"

namespace pr::cli {

namespace {

RenderOutcome renderRay(std::string_view name, const RenderRequest& r) {
  rt::TraceOptions options;
  options.integrator.kind = rt::integratorKindFromString(r.settings.ray.integrator);
  options.integrator.spp = r.settings.ray.spp;
  options.integrator.maxDepth = r.settings.ray.maxDepth;
  options.integrator.seed = r.settings.ray.seed;
  options.tileSizePx = r.settings.ray.tileSizePx;
  options.adaptive = r.settings.ray.adaptive;
  options.progress = r.progress;
  rt::TraceResult result = rt::renderRays(r.scene, r.camera, r.width, r.height, options, name, r.runtime);
  RenderOutcome out;
  out.image = std::move(result.image);
  out.rays = result.rays.total();
  out.details = "integrator " + r.settings.ray.integrator + ", spp " + std::to_string(options.integrator.spp) +
                ", max depth " + std::to_string(options.integrator.maxDepth) + "; rays: camera " +
                std::to_string(result.rays.cameraRays) + ", continuation " + std::to_string(result.rays.continuationRays) +
                ", shadow " + std::to_string(result.rays.shadowRays) + "; tasks " + std::to_string(result.tasks);
  return out;
}

// One sort point over --frames frames (the camera turned 2 pi i / N about the scene centre
// with --orbit); the image is the last frame's; the sort point is kept between frames.
RenderOutcome renderRaster(std::string_view name, const RenderRequest& r) {
  const RasterOptions& o = r.settings.raster;
  raster::SortOptions options;
  options.regions = raster::parseRegionStrategy(o.regions);
  options.tileSizePx = o.tileSizePx;
  options.compositor = o.compositor;
  options.sparse = o.sparse;
  std::unique_ptr<raster::SortPoint> sortPoint = raster::makeSortPoint(name);
  raster::SortCounters c;
  raster::RegionFramebuffer last;
  for (int frame = 0; frame < o.frames; ++frame) {
    const float angle = o.orbit ? 6.28318530718f * float(frame) / float(o.frames) : 0.0f;
    const scene::Camera camera = raster::orbitCamera(r.camera, r.scene.bounds.center(), angle);
    raster::renderFrame(*sortPoint, r.scene, raster::makeFrameView(camera, r.width, r.height), options, r.runtime,
                        last, &c);
    if (r.progress) r.progress(frame + 1, o.frames);
  }
  RenderOutcome out;
  out.image = raster::toImage(last);
  out.details = "frames " + std::to_string(o.frames) + (o.orbit ? " (orbit)" : "") + ", regions " + o.regions +
                ", tile " + std::to_string(o.tileSizePx) + " px";
  if (name == "sort-first")
    out.details += "; primitives routed " + std::to_string(c.primitivesRouted) + ", sent " +
                   std::to_string(c.primitivesSent) + ", duplicated " + std::to_string(c.primitivesDuplicated) +
                   ", migrated " + std::to_string(c.primitivesMigrated) + ", pre-transforms " +
                   std::to_string(c.preTransforms) + ", geometry repeated " + std::to_string(c.geometryRepeated);
  if (name == "sort-middle")
    out.details += "; triangles routed " + std::to_string(c.trianglesRouted) + ", sent " +
                   std::to_string(c.trianglesSent) + ", duplicated " + std::to_string(c.trianglesDuplicated);
  if (name == "sort-last")
    out.details += "; compositor " + o.compositor + (o.sparse ? " (sparse)" : " (full frame)") + ", pixels sent " +
                   std::to_string(c.pixelsSent) + " in " + std::to_string(c.compositeMessages) + " messages (" +
                   std::to_string(c.compositeBytes) + " bytes)";
  return out;
}

std::vector<RenderMethod> makeMethods() {
  std::vector<RenderMethod> methods;
  for (const rt::PartitionInfo& p : rt::partitions()) methods.push_back({p.name, MethodFamily::Ray, p.description, renderRay});
  for (const raster::SortPointInfo& s : raster::sortPoints())
    methods.push_back({s.name, MethodFamily::Raster, s.description, renderRaster});
  return methods;
}

}  // namespace

std::string_view toString(MethodFamily family) {
  return family == MethodFamily::Ray ? "ray-tracing" : "rasterization";
}

const std::vector<RenderMethod>& renderMethods() {
  static const std::vector<RenderMethod> kMethods = makeMethods();
  return kMethods;
}

const RenderMethod& findRenderMethod(std::string_view name) {
  std::string names;
  for (const RenderMethod& m : renderMethods()) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown method '" + std::string(name) + "' (expected one of: " + names + ")");
}

std::string describeRenderMethods() {
  std::string out;
  for (const RenderMethod& m : renderMethods())
    out += std::string(m.name) + " (" + std::string(toString(m.family)) + "): " + std::string(m.description) + "\n";
  return out;
}

void addRayOptions(CLI::App& command, RenderSettings& settings, FamilyOptions& family) {
  RayOptions& ray = settings.ray;
  family.emplace_back(command.add_option("--integrator", ray.integrator, "ray tracing: whitted | path")
                          ->check(CLI::IsMember({"whitted", "path"}))
                          ->capture_default_str(),
                      MethodFamily::Ray);
  family.emplace_back(command.add_option("--spp", ray.spp, "ray tracing: stratified samples per pixel")
                          ->check(CLI::Range(1, rt::kMaxSpp))
                          ->capture_default_str(),
                      MethodFamily::Ray);
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
  family.emplace_back(command.add_option("--compositor", r.compositor, "sort-last: direct-send | binary-swap (P a power of two)")
                          ->check(CLI::IsMember({"direct-send", "binary-swap"}))
                          ->capture_default_str(),
                      MethodFamily::Raster);
  family.emplace_back(command.add_flag("--sparse", r.sparse, "sort-last: composite covered pixels only"), MethodFamily::Raster);
  family.emplace_back(command.add_option("--frames", r.frames, "rasterization: frames to render (the last is written)")
                          ->check(CLI::Range(1, 100000))
                          ->capture_default_str(),
                      MethodFamily::Raster);
  family.emplace_back(command.add_flag("--orbit", r.orbit, "rasterization: the camera circles the scene centre over the frames"),
                      MethodFamily::Raster);
}

void checkFamilyOptions(const RenderMethod& method, const FamilyOptions& family) {
  for (const auto& [option, f] : family)
    if (f != method.family && option->count() > 0)
      throw InputError("option " + option->get_name() + " applies to " + std::string(toString(f)) + " methods, but '" +
                       std::string(method.name) + "' is a " + std::string(toString(method.family)) + " method");
}

}  // namespace pr::cli
