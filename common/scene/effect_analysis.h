// EffectAnalysis: which light-transport effects a scene can show at all, decided from its
// materials, lights and geometry before any ray is traced (shared/DESIGN.md rule 5). The
// RenderPlan it produces lists every effect as on or off with the reason; `--effects` forces
// effects on or off on top of it. tools/ prints the plan and hands its EffectSet to the
// integrators, which skip the work of every effect that is off and count what they skipped.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "common/scene/camera.h"
#include "common/scene/scene.h"

namespace pr::scene {

// The effects, in the order the plan lists them. Their names (toString) are what --effects
// accepts and what `info --json` writes.
enum class Effect : uint8_t {
  DirectLight,     // "direct": light from emitters reaching a surface in one step (next-event estimation)
  Shadows,         // "shadows": occlusion of that light (shadow-ray visibility tests)
  IdealSpecular,   // "specular": mirror reflection of opaque surfaces (delta lobe)
  GlossySpecular,  // "glossy": reflection rays sampled from a rough (GGX) specular lobe
  Transmission,    // "transmission": the smooth dielectric part, its refraction and Fresnel reflection
  Caustics,        // "caustics": light reaching a diffuse surface through ideal specular or refraction
  IndirectDiffuse, // "indirect": diffuse surfaces lit by light other surfaces reflect (path bounces)
  Anisotropy,      // "anisotropy": KHR_materials_anisotropy lobes
  Textures,        // "textures": texture lookups in material evaluation
  Emission,        // "emission": emissive materials seen and sampled as area lights
};
inline constexpr size_t kEffectCount = 10;
std::string_view toString(Effect effect);
// The effects in plan order.
const std::array<Effect, kEffectCount>& allEffects();

// GGX roughness below which a specular lobe is an ideal mirror. The integrators treat a lobe
// as a delta when alpha = roughness^2 < 1e-3 (raytrace/integrators/bsdf.h kDeltaAlpha, a
// lobe under about 2 degrees), i.e. roughness < sqrt(1e-3) = 0.0316; the analysis uses the
// same boundary so that "no ideal specular" means the integrators never take a mirror branch.
inline constexpr float kIdealSpecularRoughness = 0.0316227766f;

// A set of effects as bits; what the integrators read (rt::IntegratorOptions::effects).
class EffectSet {
 public:
  static constexpr EffectSet all() { return EffectSet((1u << kEffectCount) - 1u); }
  static constexpr EffectSet none() { return EffectSet(0u); }
  constexpr bool has(Effect e) const { return (bits_ >> unsigned(e)) & 1u; }
  constexpr void set(Effect e, bool on) {
    bits_ = on ? (bits_ | (1u << unsigned(e))) : (bits_ & ~(1u << unsigned(e)));
  }
  constexpr bool operator==(const EffectSet&) const = default;

 private:
  constexpr explicit EffectSet(uint32_t bits) : bits_(bits) {}
  uint32_t bits_;
};

// One line of the plan: the analysis's verdict and reason, and an override when forced.
struct EffectDecision {
  Effect effect = Effect::DirectLight;
  bool analysed = true;  // what the scene calls for
  bool on = true;        // what is simulated: analysed unless forced
  bool forced = false;   // --effects set it (on may then differ from analysed)
  std::string reason;    // names what in the scene decided `analysed`
};

struct RenderPlan {
  std::array<EffectDecision, kEffectCount> effects;

  const EffectDecision& operator[](Effect e) const { return effects[size_t(e)]; }
  EffectDecision& operator[](Effect e) { return effects[size_t(e)]; }
  bool on(Effect e) const { return (*this)[e].on; }
  EffectSet enabled() const;
  // "caustics: off - no ideal specular or transmissive surface" (forced ones say so).
  std::string line(Effect e) const;
};

// --effects NAME=on|off[,NAME=on|off...]: the forced effects, unset where not named.
struct EffectOverrides {
  std::array<std::optional<bool>, kEffectCount> forced;
  bool empty() const;
};
// Parses the --effects text; an unknown name or value, or an empty item, is a pr::InputError
// whose message lists the valid names and values. An empty text forces nothing.
EffectOverrides parseEffectOverrides(std::string_view text);

// Decides every effect for the scene. camera: the view the render uses; it decides whether
// back sides of surfaces are visible, which matters only for the geometric test (can any
// surface see another?). Without it the scene's own cameras are used, and with none that
// test assumes surfaces can see each other. Conservative throughout: an effect is off only
// when it provably cannot contribute to the image.
RenderPlan analyzeEffects(const Scene& scene, const Camera* camera = nullptr);
// The plan with the overrides applied: forced effects keep their analysis and reason.
RenderPlan applyOverrides(RenderPlan plan, const EffectOverrides& overrides);

}  // namespace pr::scene
