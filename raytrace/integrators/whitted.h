// Whitted-style ray tracing (Whitted 1980): emission, direct light with shadow rays from every
// light, ideal mirror reflection, Fresnel-weighted reflection and refraction through
// dielectrics. Registered as "whitted" (registry.cpp); shading in whitted.cpp.
#pragma once

#include "raytrace/integrators/trace_loop.h"

namespace pr::rt {

class WhittedIntegrator final : public IntegratorBase<WhittedIntegrator> {
 public:
  using IntegratorBase::IntegratorBase;
  std::string_view name() const override { return "whitted"; }
  void shade(const SurfaceInteraction& si, const RayMessage& msg, Emit& out) const override;
  // Diffuse and glossy surfaces get direct light only: no glossy reflection rays, no indirect
  // diffuse, hence no caustics (direct light sees the anisotropic lobe).
  scene::EffectSet simulated() const override {
    scene::EffectSet s = scene::EffectSet::all();
    for (scene::Effect e : {scene::Effect::GlossySpecular, scene::Effect::IndirectDiffuse, scene::Effect::Caustics})
      s.set(e, false);
    return s;
  }
};

}  // namespace pr::rt
