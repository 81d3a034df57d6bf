// TraceStats: rays traced by kind and the work skipped because the RenderPlan turned an
// effect off (common/scene/effect_analysis.h), the algorithm counters of a trace
// ("Rays/camera", "Plan/shadow_tests_skipped", ...): rays counted by the message loops
// (trace_loop.h, the partitioned tracers), skips by the integrators through Emit; summed over PEs.
#pragma once

#include <cstdint>
#include <iterator>

namespace pr::rt {

struct TraceStats {
  uint64_t cameraRays = 0;
  uint64_t continuationRays = 0;
  uint64_t shadowRays = 0;
  // Skipped work, one count per unit not done (Plan/ counters, partition/registry.cpp).
  uint64_t lightSamplesSkipped = 0;       // direct light off: punctual + area samples not taken; emission off: area samples
  uint64_t shadowTestsSkipped = 0;        // shadows off: light added without its visibility test
  uint64_t specularRaysSkipped = 0;       // ideal specular off: mirror rays not spawned
  uint64_t glossyRaysSkipped = 0;         // glossy off: rays sampled from the GGX lobe not spawned
  uint64_t transmissionRaysSkipped = 0;   // transmission off: dielectric reflection/refraction rays not spawned
  uint64_t causticRaysSkipped = 0;        // caustics off: specular rays after a diffuse or glossy bounce not spawned
  uint64_t indirectRaysSkipped = 0;       // indirect off: diffuse bounces not spawned
  uint64_t emissionSkipped = 0;           // emission off: emitter hits whose radiance was not added
  uint64_t textureEvaluationsSkipped = 0; // textures off: textured materials evaluated from their factors
  // Rays traced (the cost figure of image-space's pre-pass); skips are not work done.
  uint64_t total() const { return cameraRays + continuationRays + shadowRays; }
  TraceStats& operator+=(const TraceStats& o);
};

// Every field with the run-record counter it is put in (recordRayCounters): the one list
// that sums, records and names them.
struct TraceCounter {
  const char* name;
  uint64_t TraceStats::*field;
};
inline constexpr TraceCounter kTraceCounters[] = {
    {"Rays/camera", &TraceStats::cameraRays},
    {"Rays/continuation", &TraceStats::continuationRays},
    {"Rays/shadow", &TraceStats::shadowRays},
    {"Plan/light_samples_skipped", &TraceStats::lightSamplesSkipped},
    {"Plan/shadow_tests_skipped", &TraceStats::shadowTestsSkipped},
    {"Plan/specular_rays_skipped", &TraceStats::specularRaysSkipped},
    {"Plan/glossy_rays_skipped", &TraceStats::glossyRaysSkipped},
    {"Plan/transmission_rays_skipped", &TraceStats::transmissionRaysSkipped},
    {"Plan/caustic_rays_skipped", &TraceStats::causticRaysSkipped},
    {"Plan/indirect_rays_skipped", &TraceStats::indirectRaysSkipped},
    {"Plan/emission_skipped", &TraceStats::emissionSkipped},
    {"Plan/texture_evaluations_skipped", &TraceStats::textureEvaluationsSkipped},
};

static_assert(sizeof(TraceStats) == std::size(kTraceCounters) * sizeof(uint64_t), "every TraceStats field is in kTraceCounters");

inline TraceStats& TraceStats::operator+=(const TraceStats& o) {
  for (const TraceCounter& c : kTraceCounters) this->*c.field += o.*c.field;
  return *this;
}

}  // namespace pr::rt
