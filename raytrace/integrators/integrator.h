// Integrators as a ray-message state machine: cameraRays makes the primary RayMessages of a
// pixel rectangle, shade turns one hit into film contributions and new messages (shadow,
// reflection, refraction, path continuation), miss handles a ray that left the scene (a
// shadow ray's contribution is added iff it is unoccluded). Every tracer — sequential,
// image-space, object-space, object partitioning — calls these same functions and differs
// only in where a message is traced (shared/DESIGN.md rule 4). Whitted (whitted.cpp) and the
// path tracer (path_tracer.cpp) are concrete classes behind one std::variant: no per-ray
// virtual call.
#pragma once

#include <cstdint>
#include <string_view>
#include <variant>
#include <vector>

#include "common/scene/camera.h"
#include "common/scene/scene.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/film.h"
#include "raytrace/integrators/light_sampler.h"
#include "raytrace/integrators/ray_message.h"
#include "raytrace/integrators/sampling.h"

namespace pr::rt {

enum class IntegratorKind : uint8_t { Whitted, Path };
std::string_view toString(IntegratorKind kind);
// "whitted" | "path"; throws pr::InputError naming the value otherwise.
IntegratorKind integratorKindFromString(std::string_view name);

inline constexpr int kMaxDepthLimit = 255;  // RayMessage::depth is 8 bits
inline constexpr int kMaxSpp = 65535;       // RayMessage::sample is 16 bits

struct IntegratorOptions {
  IntegratorKind kind = IntegratorKind::Path;
  int spp = 1;        // samples per pixel, stratified (--spp)
  int maxDepth = 8;   // surface interactions a path may shade (--max-depth); >= 1
  uint64_t seed = 1;  // --seed
};

// Where shading results go: radiance into the Film, spawned rays into the caller's queue. A
// tracer that routes rays to other PEs takes them from the queue after the call.
class Emit {
 public:
  Emit(Film& film, std::vector<RayMessage>& rays) : film_(&film), rays_(&rays) {}
  void addRadiance(uint32_t pixel, const glm::vec3& radiance) { film_->add(pixel, radiance); }
  void push(const RayMessage& message) { rays_->push_back(message); }

 private:
  Film* film_;
  std::vector<RayMessage>* rays_;
};

// A rectangle of pixels [x0, x1) x [y0, y1): one image-space tile, or the whole image.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int64_t pixels() const { return int64_t(x1 - x0) * int64_t(y1 - y0); }
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
  // Next-event estimation at a hit: one shadow ray per punctual light and one area-light
  // sample, each carrying throughput * f * L * cos / pdf (times the MIS weight against BSDF
  // sampling when mis is set). opaqueWeight scales the diffuse + glossy part.
  void directLight(const SurfaceInteraction& si, const ShadingMaterial& m, const Frame& frame, const glm::vec3& woLocal,
                   const RayMessage& msg, float opaqueWeight, bool mis, Emit& out) const;
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
struct ShadingFrame {
  glm::vec3 ng, ns;
  Frame frame;
  glm::vec3 woLocal;
  explicit ShadingFrame(const SurfaceInteraction& si);
};

// Whitted-style ray tracing (Whitted 1980): emission, direct light with shadow rays from every
// light, ideal mirror reflection, Fresnel-weighted reflection and refraction through dielectrics.
class WhittedIntegrator {
 public:
  explicit WhittedIntegrator(const IntegratorContext& ctx) : ctx_(&ctx) {}
  void shade(const SurfaceInteraction& si, const RayMessage& msg, Emit& out) const;

 private:
  const IntegratorContext* ctx_;
};

// Brute-force unidirectional path tracing (Kajiya 1986) with next-event estimation, multiple
// importance sampling of emitters (power heuristic, Veach 1997) and Russian roulette.
class PathIntegrator {
 public:
  explicit PathIntegrator(const IntegratorContext& ctx) : ctx_(&ctx) {}
  void shade(const SurfaceInteraction& si, const RayMessage& msg, Emit& out) const;

 private:
  const IntegratorContext* ctx_;
};

class Integrator {
 public:
  Integrator(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
             const IntegratorOptions& options);
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  const IntegratorOptions& options() const { return ctx_.options(); }
  const IntegratorContext& context() const { return ctx_; }

  // Primary rays of every pixel of `rect`, options().spp stratified samples each, appended to
  // out in pixel order then sample order.
  void cameraRays(const PixelRect& rect, std::vector<RayMessage>& out) const;
  // A camera or continuation ray hit si (made by makeInteraction from msg.ray's closest hit).
  void shade(const SurfaceInteraction& si, const RayMessage& msg, Emit& out) const {
    std::visit([&](const auto& integrator) { integrator.shade(si, msg, out); }, impl_);
  }
  // A ray found nothing: a shadow ray adds its contribution (unoccluded); any other ray sees
  // the black background.
  void miss(const RayMessage& msg, Emit& out) const {
    if (msg.kind == RayKind::Shadow) out.addRadiance(msg.pixel, msg.throughput);
  }

 private:
  IntegratorContext ctx_;
  scene::Camera camera_;
  std::variant<WhittedIntegrator, PathIntegrator> impl_;
};

}  // namespace pr::rt
