// Pass 2 of Jensen's two-pass method, `--integrator photonmap` (seed chapter "Global
// Illumination in Complex Scenes using Photon Maps", section 2.4): the radiance at a surface
// seen from the eye split into
//   - emission and direct light, by next-event estimation (shadow rays; several on area lights),
//   - ideal specular reflection and refraction, by one ray each (Fresnel-weighted),
//   - glossy reflection (the rough GGX lobe, anisotropic for KHR_materials_anisotropy, sheen and
//     clear coat), by Monte Carlo rays, as many as the lobes' roughness asks,
//   - caustics, straight from the caustic map (cone filter) with the full non-delta BRDF, and
//     glossy caustics (light that came along glossy bounces but no diffuse one) from the
//     global map where they land,
//   - indirect diffuse light, by final gathering whose hits read the global map, through an
//     irradiance cache with Ward-Heckbert gradients built in a pre-pass over the image.
// Hits of glossy and gathering rays read the global map for all their light after a diffuse
// bounce (Jensen's rule), with the hit's full non-delta BRDF and each photon's direction; the
// photons' PhotonPath bits keep each path in exactly one term.
// The BSDF is the other integrators' (raytrace/integrators/bsdf.h), in both passes. The pre-pass (prePass: photon tracing, both
// kd-trees, cache records) runs through the render's own tracer before the render; every shade
// call after it only reads the maps and the cache, so shading is the same ray-message state
// machine as the other integrators and gives the same image for every tracer, P and schedule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "photonmap/density_estimate.h"
#include "photonmap/irradiance_cache.h"
#include "photonmap/kd_tree.h"
#include "photonmap/photon_tracer.h"
#include "photonmap/precomputed_irradiance.h"
#include "raytrace/integrators/trace_loop.h"

namespace pr::pm {

// What the image shows: the full solution, or one map's radiance estimate at the first
// surface seen (the seed's figure 3, for inspecting a map).
enum class PhotonView : std::uint8_t { Full, GlobalMap, CausticMap };
std::string_view toString(PhotonView view);
// "full" | "global-map" | "caustic-map"; throws pr::InputError listing them otherwise.
PhotonView parsePhotonView(std::string_view text);

struct PhotonMapSettings {
  std::size_t globalPhotons = 200000;   // --photons: emitted for the global map
  std::size_t causticPhotons = 100000;  // --caustic-photons
  int globalK = 50;                     // --k: photons per global-map estimate
  int causticK = 60;                    // --caustic-k
  // Maximum search radii in scene units; 0 = a fraction of the scene's bounding diagonal
  // (kAutoGlobalRadius, kAutoCausticRadius).
  float globalRadius = 0.0f;            // --radius
  float causticRadius = 0.0f;           // --caustic-radius
  int gatherRays = 256;                 // --gather: rays per irradiance-cache record
  float cacheAccuracy = 0.25f;          // --cache-accuracy: Ward's a
  int fallbackGatherRays = 64;          // gather rays as messages where no record covers a point
  int areaLightSamples = 4;             // area-light shadow rays per pixel, at least one per sample
  int maxGlossyRays = 16;               // glossy rays at a first hit of roughness 1 (fewer when smoother)
  PhotonView view = PhotonView::Full;   // --view
  std::size_t photonBatch = 4096;       // photons per task of pass 1
  // Every n-th global photon carries a precomputed irradiance estimate that gathering reads
  // (Christensen 1999); 0 = none, every gather hit makes its own density estimate.
  int irradianceStride = 4;
};

inline constexpr float kAutoGlobalRadius = 0.05f;    // x the scene's bounding diagonal
inline constexpr float kAutoCausticRadius = 0.015f;  // x the scene's bounding diagonal

class PhotonMapIntegrator final : public rt::IntegratorBase<PhotonMapIntegrator> {
 public:
  PhotonMapIntegrator(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                      const rt::IntegratorOptions& options, const PhotonMapSettings& settings);

  std::string_view name() const override { return "photonmap"; }
  // Every effect: anisotropic materials get the Ward lobe (ward_brdf.h).
  scene::EffectSet simulated() const override { return scene::EffectSet::all(); }
  bool hasPrePass() const override { return true; }
  // Through the render's tracer: pass 1 (photon_pass.h, stage "photon merge" and the photon
  // program's), the kd-trees, the precomputed irradiance, the maps' broadcast, and the
  // irradiance cache (irradiance_cache_pass.h), which broadcasts its records level by level.
  void prePass(rt::PrePassTracer& tracer, par::Runtime& rt) const override;
  void shade(const rt::SurfaceInteraction& si, const rt::RayMessage& msg, rt::Emit& out) const override;
  // Eye paths see the environment; gathering and glossy rays do not (light sampling at their
  // origin counted it as direct light).
  void miss(const rt::RayMessage& msg, rt::Emit& out) const override {
    if (msg.kind == rt::RayKind::Gather || (msg.kind == rt::RayKind::Continuation && msg.bsdfPdf > 0.0f)) return;
    Integrator::miss(msg, out);
  }

  const PhotonMapSettings& settings() const { return settings_; }
  // What the pre-pass built (valid after prePass).
  const PhotonMaps& maps() const { return state_->maps; }
  const IrradianceCache& cache() const { return state_->cache; }
  const PrecomputedIrradiance& precomputedIrradiance() const { return state_->irradiance; }
  const DensityOptions& globalDensity() const { return globalDensity_; }
  const DensityOptions& causticDensity() const { return causticDensity_; }

 private:
  // The maps and the cache: written once by prePass on the controlling thread before the trace
  // stage, read-only by every PE afterwards (the integrator itself is shared as const).
  struct State {
    PhotonMaps maps;
    PrecomputedIrradiance irradiance;
    IrradianceCache cache;
    bool glossyCaustics = false;  // some global photon took a glossy bounce and no diffuse one
  };
  // The weight of sample `sample`'s caustic and indirect estimates: 0 outside the stratified
  // subset of the pixel's samples that reads them, the subset's inverse share inside it.
  float smoothWeight(std::uint16_t sample) const;

  PhotonMapSettings settings_;
  scene::Camera camera_;
  int areaSamples_ = 1;            // area-light samples per shading point
  glm::ivec2 smoothBlock_{1, 1};   // strata per block of the smooth terms' sub-grid
  int smoothStrataX_ = 1;
  DensityOptions globalDensity_, causticDensity_;
  std::unique_ptr<State> state_;
};

// The registry entry ("photonmap" -> a factory building the integrator with `settings`), added
// to the program's registry by tools/integrators.cpp.
rt::IntegratorInfo photonMapIntegratorEntry(const PhotonMapSettings& settings = {});

}  // namespace pr::pm
