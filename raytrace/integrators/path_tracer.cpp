// Path-tracing shading of one hit (Kajiya 1986), the reference the photon map is checked
// against: emission weighted against light sampling by MIS, next-event estimation, one
// sampled continuation (dielectric or opaque lobe), Russian roulette from depth 3 on. Each
// hit spawns at most one continuation, so a path is a chain of messages. Runs on any PE.
// The RenderPlan's effects that are off end the path where the lobe chosen for the next ray
// belongs to them (counted in TraceStats); the lobe is chosen from the same random numbers as
// always, so paths of the effects that stay on are unchanged.
#include <algorithm>
#include <cmath>

#include "raytrace/integrators/path_tracer.h"

namespace pr::rt {

namespace {
// Roulette starts after this many bounces: short paths carry most of the image's energy.
constexpr int kRouletteDepth = 3;
// Survival probability cap: even a bright path ends with probability >= 5% per bounce.
constexpr float kMaxSurvival = 0.95f;
}  // namespace

void PathIntegrator::shade(const SurfaceInteraction& si, const RayMessage& incoming, Emit& out) const {
  const IntegratorContext& ctx = context();
  ShadingMaterial m = ctx.material(si, out);
  const RayMessage msg = ctx.arrived(si, m, incoming);

  // Emission: full weight for camera rays and after delta events; otherwise MIS against the
  // light sample taken at the previous vertex (power heuristic).
  const glm::vec3 le = ctx.emitted(m, si, out);
  if (maxComponent(le) > 0.0f) {
    float weight = 1.0f;
    if (msg.kind == RayKind::Continuation && msg.bsdfPdf < 0.0f) {
      weight = 0.0f;  // light sampling at the previous vertex took this light in full (no MIS)
    } else if (msg.kind == RayKind::Continuation && msg.bsdfPdf > 0.0f) {
      const float distance = si.t * glm::length(msg.ray.direction);
      const float cosLight = std::fabs(glm::dot(si.geometricNormal, si.wo));
      const float pl = ctx.lights().areaPdf(si.triangle, distance, cosLight);
      weight = msg.bsdfPdf * msg.bsdfPdf / (msg.bsdfPdf * msg.bsdfPdf + pl * pl);
    }
    out.addRadiance(msg.pixel, msg.throughput * le * weight);
  }
  if (msg.depth >= ctx.options().maxDepth) return;

  const ShadingFrame sf(si, m);
  const float dielectric = m.dielectricWeight();
  const float opaque = 1.0f - dielectric;
  // MIS between light and BSDF sampling needs both: when the plan skips a rough lobe's
  // continuation (indirect or glossy off), light sampling alone carries the direct light
  // (also the environment's, which no surface analysis sees), and a continuation still spawned
  // must not add the light it reaches again: it carries bsdfPdf < 0.
  const float ps = specularProbability(m, sf.woLocal.z);
  const bool diffuseLobe = ps < 1.0f, glossyLobe = (ps > 0.0f && !m.deltaSpecular()) || m.hasClearcoat();
  const bool mis = (!diffuseLobe || ctx.simulates(scene::Effect::IndirectDiffuse)) &&
                   (!glossyLobe || ctx.simulates(scene::Effect::GlossySpecular));
  ctx.directLight(si, m, sf.frame, sf.woLocal, msg, opaque, mis, out);

  // Choose the part: the dielectric with probability `dielectric` (its selection probability
  // cancels its weight), else the opaque lobes, whose sample is divided by `opaque`.
  const float lobe = ctx.sample(msg, Dim::kLobe);
  // A path that arrived by a diffuse or glossy bounce (a non-delta BSDF sample, bsdfPdf > 0)
  // and continues through an ideal mirror or a refraction is a caustic path (L S+ D E read
  // from the light).
  const bool afterRoughBounce = msg.kind == RayKind::Continuation && msg.bsdfPdf != 0.0f;
  auto skip = [&](uint64_t TraceStats::*counter) { ++(out.stats().*counter); };
  glm::vec3 wi;
  glm::vec3 throughput;
  float pdf = 0.0f;
  if (lobe < dielectric) {
    if (!ctx.simulates(scene::Effect::Transmission)) return skip(&TraceStats::transmissionRaysSkipped);
    if (afterRoughBounce && !ctx.simulates(scene::Effect::Caustics)) return skip(&TraceStats::causticRaysSkipped);
    const DielectricSample d =
        sampleDielectric(m, si, sf, lobe / dielectric, ctx.sample(msg, Dim::kBsdfU), ctx.sample(msg, Dim::kBsdfV));
    if (!d.valid) return;
    wi = d.wi;
    throughput = msg.throughput * d.weight;
  } else {
    const float u = std::min(dielectric > 0.0f ? (lobe - dielectric) / opaque : lobe, kOneMinusEpsilon);
    // The plan may skip the lobe sampleOpaque will take for u.
    const OpaqueLobe chosen = opaqueLobe(m, sf.woLocal, u);
    if (chosen == OpaqueLobe::Specular && m.deltaSpecular()) {
      if (!ctx.simulates(scene::Effect::IdealSpecular)) return skip(&TraceStats::specularRaysSkipped);
      if (afterRoughBounce && !ctx.simulates(scene::Effect::Caustics)) return skip(&TraceStats::causticRaysSkipped);
    } else if (chosen != OpaqueLobe::Diffuse) {
      if (!ctx.simulates(scene::Effect::GlossySpecular)) return skip(&TraceStats::glossyRaysSkipped);
    } else if (!ctx.simulates(scene::Effect::IndirectDiffuse)) {
      return skip(&TraceStats::indirectRaysSkipped);
    }
    const BsdfSample s = sampleOpaque(m, sf.woLocal, u, ctx.sample(msg, Dim::kBsdfU), ctx.sample(msg, Dim::kBsdfV));
    if (!s.valid) return;
    wi = sf.frame.toWorld(s.wi);
    // A reflection must leave on the side it arrived from (no leaks through the surface).
    if (glm::dot(wi, sf.ng) <= 0.0f) return;
    // The opaque lobes were picked with probability `opaque`; their weights are their own.
    throughput = msg.throughput * s.weight / opaque;
    pdf = s.delta ? 0.0f : mis ? s.pdf * opaque : -1.0f;
  }

  // Russian roulette (Arvo and Kirk 1990): survive with q = max throughput component.
  if (msg.depth + 1 >= kRouletteDepth) {
    const float q = std::min(kMaxSurvival, maxComponent(throughput));
    if (!(q > 0.0f) || ctx.sample(msg, Dim::kRoulette) >= q) return;
    throughput /= q;
  }
  if (!(maxComponent(throughput) > 0.0f) || !isFinite(throughput)) return;
  out.push(ctx.continuation(si, msg, wi, throughput, pdf));
}

void PathIntegrator::miss(const RayMessage& msg, Emit& out) const {
  const scene::Environment* env = context().scene().environment.get();
  if (msg.kind == RayKind::Continuation && msg.bsdfPdf < 0.0f) return;  // its light was sampled in full
  if (msg.kind == RayKind::Shadow || !env || msg.kind != RayKind::Continuation || !(msg.bsdfPdf > 0.0f)) {
    Integrator::miss(msg, out);
    return;
  }
  if (!context().simulates(scene::Effect::DirectLight)) return Integrator::miss(msg, out);  // no light sample to weigh against
  const glm::vec3 dir = glm::normalize(msg.ray.direction);
  const float pl = env->pdf(dir);
  const float weight = msg.bsdfPdf * msg.bsdfPdf / (msg.bsdfPdf * msg.bsdfPdf + pl * pl);
  out.addRadiance(msg.pixel, msg.throughput * env->radiance(dir) * weight);
}

}  // namespace pr::rt
