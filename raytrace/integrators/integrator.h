// Integrators as a ray-message state machine: cameraRays makes the primary RayMessages of a
// pixel rectangle, shade turns one hit into film contributions and new messages (shadow,
// reflection, refraction, path continuation), miss handles a ray that left the scene (a
// shadow ray's contribution is added iff it is unoccluded). Every tracer — sequential,
// image-space, object-space, object partitioning — calls these same functions and differs
// only in where a message is traced (shared/DESIGN.md rule 4). The Integrator interface is
// here; Whitted (whitted.h) and the path tracer (path_tracer.h) implement it through
// IntegratorBase (trace_loop.h), and an IntegratorRegistry lists them (registry.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include "common/scene/camera.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
#include "common/util/registry.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/film.h"
#include "raytrace/integrators/light_sampler.h"
#include "raytrace/integrators/ray_message.h"
#include "raytrace/integrators/sampling.h"
#include "raytrace/integrators/trace_stats.h"

namespace pr::par {
class Runtime;
}

namespace pr::rt {

// The built-in integrators, for library callers and tests that pick one without a registry
// (TraceOptions::integrator.kind); programs choose by name from an IntegratorRegistry.
enum class IntegratorKind : uint8_t { Whitted, Path };
std::string_view toString(IntegratorKind kind);  // its registry name: "whitted" | "path"

inline constexpr int kMaxDepthLimit = 255;  // RayMessage::depth is 8 bits
inline constexpr int kMaxSpp = 65535;       // RayMessage::sample is 16 bits

struct IntegratorOptions {
  IntegratorKind kind = IntegratorKind::Path;  // used only where no Integrator object is given
  int spp = 1;        // samples per pixel, stratified (--spp)
  int maxDepth = 8;   // surface interactions a path may shade (--max-depth); >= 1
  uint64_t seed = 1;  // --seed
  // The effects to simulate: the RenderPlan's (common/scene/effect_analysis.h), filled by
  // tools/ from analyzeEffects and --effects. The work of an effect that is off is skipped
  // and counted in TraceStats; the random numbers of the rest do not move, since each is a
  // function of (seed, pixel, sample, depth, dim). Everything on by default.
  scene::EffectSet effects = scene::EffectSet::all();
};

// Where shading results go: radiance into the Film, spawned rays into the caller's queue,
// skipped work into the PE's TraceStats. A tracer that routes rays to other PEs takes them
// from the queue after the call. pe: the PE shading, for an integrator that keeps results of
// its own per PE (a pre-pass program's deposits, see PrePassTracer).
class Emit {
 public:
  Emit(Film& film, std::vector<RayMessage>& rays, TraceStats& stats, int pe)
      : film_(&film), rays_(&rays), stats_(&stats), pe_(pe) {}
  void addRadiance(uint32_t pixel, const glm::vec3& radiance) { film_->add(pixel, radiance); }
  void push(const RayMessage& message) { rays_->push_back(message); }
  TraceStats& stats() { return *stats_; }
  int pe() const { return pe_; }

 private:
  Film* film_;
  std::vector<RayMessage>* rays_;
  TraceStats* stats_;
  int pe_;
};


// What both integrators read: the scene, camera, image size, options and light sampler.
class IntegratorContext {
 public:
  IntegratorContext(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                    const IntegratorOptions& options);

  const scene::Scene& scene() const { return *scene_; }
  const IntegratorOptions& options() const { return options_; }
  const LightSampler& lights() const { return lights_; }
  int width() const { return width_; }
  int height() const { return height_; }

  float sample(const RayMessage& m, uint32_t dim) const {
    return sample1D(options_.seed, m.pixel, m.sample, m.depth, dim);
  }
  bool simulates(scene::Effect e) const { return options_.effects.has(e); }
  // The material at a hit, its textures ignored when the plan turns textures off (counted).
  ShadingMaterial material(const SurfaceInteraction& si, Emit& out) const;
  // The message as it arrives at si: its throughput attenuated when the segment ran inside an
  // absorbing solid (KHR_materials_volume, volumeTransmittance). Every integrator shades this.
  RayMessage arrived(const SurfaceInteraction& si, const ShadingMaterial& m, const RayMessage& msg) const {
    RayMessage at = msg;
    at.throughput *= volumeTransmittance(m, si, msg.ray);
    return at;
  }
  // The emitted radiance at a hit towards wo; zero (counted) when emission is off.
  glm::vec3 emitted(const ShadingMaterial& m, const SurfaceInteraction& si, Emit& out) const;
  // Next-event estimation at a hit: one shadow ray per punctual light and one area-light
  // sample, each carrying throughput * f * L * cos / pdf (times the MIS weight against BSDF
  // sampling when mis is set), f the opaque lobes as evalOpaque weighs them. opaqueProbability:
  // how often the integrator's BSDF sampling picks the opaque lobes (the MIS weight's pdf is
  // that times pdfOpaque; at 0, clear glass, nothing is sampled). areaSamples > 1
  // takes that many area-light samples, each weighted 1 / areaSamples (sample 0 on the Dim::
  // kLight* dimensions, sample i on Dim::kLightExtra + 3 (i - 1) ...). Plan: nothing
  // with direct light off, no area sample with emission off, and with shadows off the
  // contribution goes straight to the film (what an unoccluded shadow ray adds on its miss).
  // eval, when given, replaces the opaque BSDF's evaluation f(wo, wi) (local vectors of frame,
  // without cos): an integrator's own lobe (the photon map's anisotropic Ward). MIS is then off.
  using OpaqueEval = std::function<glm::vec3(const glm::vec3& woLocal, const glm::vec3& wiLocal)>;
  void directLight(const SurfaceInteraction& si, const ShadingMaterial& m, const Frame& frame, const glm::vec3& woLocal,
                   const RayMessage& msg, float opaqueProbability, bool mis, Emit& out, int areaSamples = 1,
                   const OpaqueEval* eval = nullptr) const;
  // Pushes ray when the plan simulates `effect`, else counts it in TraceStats::*skipped.
  void spawn(scene::Effect effect, uint64_t TraceStats::*skipped, const RayMessage& ray, Emit& out) const {
    if (simulates(effect))
      out.push(ray);
    else
      ++(out.stats().*skipped);
  }
  // A continuation ray from si in direction wi.
  RayMessage continuation(const SurfaceInteraction& si, const RayMessage& msg, const glm::vec3& wi,
                          const glm::vec3& throughput, float bsdfPdf) const;

 private:
  const scene::Scene* scene_;
  scene::Camera camera_;
  int width_, height_;
  IntegratorOptions options_;
  LightSampler lights_;
};

// The shading frame on the side of wo: geometric and shading normals flipped to the side the
// ray came from, the shading normal replaced by the geometric one when wo is below it.
// Given the material, its normal-mapped normal is the shading normal, and the material's
// clear-coat normal is expressed in the frame.
struct ShadingFrame {
  glm::vec3 ng, ns;
  Frame frame;
  glm::vec3 woLocal;
  explicit ShadingFrame(const SurfaceInteraction& si);
  ShadingFrame(const SurfaceInteraction& si, ShadingMaterial& m);

 private:
  ShadingFrame(const SurfaceInteraction& si, const glm::vec3& shadingNormal);
};

// The dielectric (refracting) part's scattering, shared by every integrator and the photon
// tracer: reflection with probability F, else refraction (the choice's probability cancels
// the Fresnel weight), about the shading normal when the surface is smooth and about a GGX
// microfacet normal drawn for (u, v) when it is rough (frosted glass; Walter et al. 2007).
// choice in [0, 1). weight = the microfacet weight (1 when smooth) times the transmission tint
// on refraction, and for eye paths (Transport::Radiance) refractedRadianceScale too. delta:
// smooth. valid false when the sample is lost: a microfacet facing away, a rough reflection
// that leaves below the surface or a refraction that stays above it.
enum class Transport { Radiance, Flux };  // what a path carries: eye paths radiance, photons flux
struct DielectricSample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};
  bool reflected = false;
  bool delta = true;
  bool valid = false;
};
DielectricSample sampleDielectric(const ShadingMaterial& m, const SurfaceInteraction& si, const ShadingFrame& sf, float choice,
                                  float u, float v, Transport transport = Transport::Radiance);

struct TraceStats;  // trace_stats.h
class Bvh;          // raytrace/core/bvh.h
class Integrator;

// What an integrator's pre-pass traces with: the render's own tracer. A pre-pass is a series
// of programs, each an Integrator over a virtual image of its own (one pixel per photon, per
// irradiance-cache record, ...) whose cameraRays start its paths and whose shade keeps its
// results per PE (Emit::pe) instead of adding radiance; the tracer runs a program as it runs a
// render - tiles as tasks in image-space, rays as messages between owners in object-space and
// object partitioning - but assembles no image. So every tracer runs the same pre-pass, with
// the same results, and every transfer it makes is counted in the run record.
class PrePassTracer {
 public:
  virtual ~PrePassTracer() = default;
  // Runs the program's paths to completion on the render's PEs (stages in the run record).
  // tileSizePx: the task granularity in the program's pixels (image-space).
  virtual void trace(const std::shared_ptr<const Integrator>& program, int tileSizePx) = 0;
};

// An integrator: how a hit becomes radiance and new rays. The interface every tracer drives;
// concrete integrators derive from IntegratorBase<Self> (trace_loop.h) and are listed in an
// IntegratorRegistry. Built once per render for its scene, camera and image size, then shared
// read-only by every PE.
//
// Dispatch: the world-model tracers (sequential, image-space) make one virtual call per task,
// traceToCompletion, whose message loop IntegratorBase instantiates for the concrete class, so
// shade is a direct call inside it. The message-passing tracers (object-space, object) call
// shade once per hit message they handle, at the granularity of the message itself.
class Integrator {
 public:
  Integrator(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
             const IntegratorOptions& options);
  virtual ~Integrator() = default;
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  virtual std::string_view name() const = 0;  // its registry name, e.g. "path"
  const IntegratorOptions& options() const { return ctx_.options(); }
  const IntegratorContext& context() const { return ctx_; }

  // The effects this integrator simulates at all (the render prints the others as not
  // simulated); the plan's work is skipped only among these.
  virtual scene::EffectSet simulated() const { return scene::EffectSet::all(); }
  // Primary rays of every pixel of `rect`, options().spp stratified samples each, appended to
  // out in pixel order then sample order.
  void cameraRays(const PixelRect& rect, std::vector<RayMessage>& out) const { cameraRays(rect, options().spp, out); }
  // The same with spp samples per pixel (image-space's one-sample cost pre-pass): sample s of
  // a pixel is the same ray whatever spp, for s < spp, only when spp matches the render's. A
  // pre-pass program overrides it to start its own paths (photons, gather rays).
  virtual void cameraRays(const PixelRect& rect, int spp, std::vector<RayMessage>& out) const;
  // A pre-pass before the render (the photon map's photon tracing and irradiance cache), run
  // by renderRays on the controlling thread through the render's own tracer (PrePassTracer),
  // its stages recorded in rt's run record; afterwards the integrator is read-only again.
  virtual bool hasPrePass() const { return false; }
  virtual void prePass(PrePassTracer& tracer, par::Runtime& rt) const {
    (void)tracer;
    (void)rt;
  }
  // A camera or continuation ray hit si (made by makeInteraction from msg.ray's closest hit).
  virtual void shade(const SurfaceInteraction& si, const RayMessage& msg, Emit& out) const = 0;
  // A ray found nothing: a shadow ray adds its contribution (unoccluded); any other ray sees
  // the scene's environment in full (black without one). An integrator that samples the
  // environment where a BSDF sample could also reach it weighs this (the path tracer's MIS).
  virtual void miss(const RayMessage& msg, Emit& out) const {
    if (msg.kind == RayKind::Shadow) {
      out.addRadiance(msg.pixel, msg.throughput);
      return;
    }
    if (const scene::Environment* env = ctx_.scene().environment.get())
      out.addRadiance(msg.pixel, msg.throughput * env->radiance(glm::normalize(msg.ray.direction)));
  }
  // The message loop of a PE that holds the whole world: traces every message in queue and
  // every message shading spawns until none is left, against bvh (over context().scene()).
  // One call per task; implemented by IntegratorBase (trace_loop.h).
  virtual void traceToCompletion(const Bvh& bvh, std::vector<RayMessage>& queue, Film& film,
                                 TraceStats& stats, int pe) const = 0;

 private:
  IntegratorContext ctx_;
  scene::Camera camera_;
};

// What an integrator is built for: one render's scene, camera, image size and options.
struct IntegratorSetup {
  const scene::Scene& scene;
  const scene::Camera& camera;
  int width = 0, height = 0;
  IntegratorOptions options;
};

// Registry of integrators: name -> factory -> description; feeds --integrator, its --help,
// validation and the render summary. A std::function factory, so an entry added by a library
// further down the link order can capture its own settings (photon counts, ...).
using IntegratorFactory = std::function<std::shared_ptr<const Integrator>(const IntegratorSetup&)>;
using IntegratorInfo = RegistryEntry<IntegratorFactory>;
using IntegratorRegistry = Registry<IntegratorFactory>;
// The integrators of this library (registry.cpp): whitted, path. photonmap links raytrace,
// never the reverse, so a program assembles its registry explicitly: a copy of this one plus
// add() of the photon-map entries (tools/integrators.cpp); see common/util/registry.h for
// why not static self-registration.
const IntegratorRegistry& builtinIntegrators();
// The built-in integrator `kind` names (the default of a TraceJob that carries none).
std::shared_ptr<const Integrator> makeBuiltinIntegrator(IntegratorKind kind, const IntegratorSetup& setup);

}  // namespace pr::rt
