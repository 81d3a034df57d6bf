// Brute-force unidirectional path tracing (Kajiya 1986) with next-event estimation, multiple
// importance sampling of emitters (power heuristic, Veach 1997) and Russian roulette; the
// reference the photon map is checked against. Registered as "path" (registry.cpp); shading
// in path_tracer.cpp.
#pragma once

#include "raytrace/integrators/trace_loop.h"

namespace pr::rt {

class PathIntegrator final : public IntegratorBase<PathIntegrator> {
 public:
  using IntegratorBase::IntegratorBase;
  std::string_view name() const override { return "path"; }
  void shade(const SurfaceInteraction& si, const RayMessage& msg, Emit& out) const override;
  // The environment seen by a BSDF-sampled ray, weighted against its light sample (MIS).
  void miss(const RayMessage& msg, Emit& out) const override;
  // Every effect (anisotropy by the BSDF's anisotropic GGX lobe, bsdf.h).
  scene::EffectSet simulated() const override { return scene::EffectSet::all(); }
};

}  // namespace pr::rt
