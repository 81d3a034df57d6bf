// Whitted-style shading of one hit (Whitted 1980; seed section 5.1): emission, direct light
// through shadow rays, an ideal mirror ray for mirror-like metals, and a Fresnel split into
// reflection and refraction at dielectrics (total internal reflection included). Diffuse and
// glossy surfaces get direct light only. Runs on the PE holding the message. The RenderPlan's
// effects (IntegratorOptions::effects) that are off skip their rays, counted in TraceStats.
#include <cmath>

#include "raytrace/integrators/whitted.h"

namespace pr::rt {

namespace {
// Spawned rays weaker than this add nothing visible (below 1/4096 of a camera ray's weight).
constexpr float kMinThroughput = 1.0f / 4096.0f;
}  // namespace

void WhittedIntegrator::shade(const SurfaceInteraction& si, const RayMessage& incoming, Emit& out) const {
  const IntegratorContext& ctx = context();
  ShadingMaterial m = ctx.material(si, out);
  const RayMessage msg = ctx.arrived(si, m, incoming);
  // Every ray of a Whitted tracer reaches an emitter only through camera, mirror or
  // refraction paths, which light sampling never covers, so emission counts fully.
  const glm::vec3 le = ctx.emitted(m, si, out);
  if (maxComponent(le) > 0.0f) out.addRadiance(msg.pixel, msg.throughput * le);
  if (msg.depth >= ctx.options().maxDepth) return;

  const ShadingFrame sf(si, m);
  const float dielectric = m.dielectricWeight();
  const float opaque = 1.0f - dielectric;
  ctx.directLight(si, m, sf.frame, sf.woLocal, msg, opaque, false, out);

  // Mirror-like metals and smooth dielectric coats: one ideal reflection ray.
  if (opaque > 0.0f && m.deltaSpecular()) {
    const glm::vec3 f = m.specularFresnel(sf.woLocal.z);  // F0 and F90 hold the opaque share
    const glm::vec3 t = msg.throughput * f;
    if (maxComponent(t) > kMinThroughput) {
      const glm::vec3 wi = sf.frame.toWorld(glm::vec3(-sf.woLocal.x, -sf.woLocal.y, sf.woLocal.z));
      if (glm::dot(wi, sf.ng) > 0.0f)
        ctx.spawn(scene::Effect::IdealSpecular, &TraceStats::specularRaysSkipped, ctx.continuation(si, msg, wi, t, 0.0f), out);
    }
  }

  // Dielectric (smooth: Whitted's one ray each way, whatever the roughness): reflect with F,
  // refract with 1 - F tinted by the base colour once per solid; all of it reflects under
  // total internal reflection.
  if (dielectric > 0.0f) {
    const float eta = si.frontFace ? m.ior : 1.0f / m.ior;
    const float cosI = glm::dot(sf.ns, si.wo);
    const float fr = fresnelDielectric(cosI, eta);
    const glm::vec3 reflected = 2.0f * cosI * sf.ns - si.wo;
    const glm::vec3 tr = msg.throughput * (dielectric * fr);
    if (maxComponent(tr) > kMinThroughput)
      ctx.spawn(scene::Effect::Transmission, &TraceStats::transmissionRaysSkipped,
                ctx.continuation(si, msg, glm::normalize(reflected), tr, 0.0f), out);
    glm::vec3 wt;
    if (fr < 1.0f && refractDirection(si.wo, sf.ns, eta, wt)) {
      const glm::vec3 tt =
          msg.throughput * m.transmissionTint(si.frontFace) * (dielectric * (1.0f - fr) * m.refractedRadianceScale(si.frontFace));
      if (maxComponent(tt) > kMinThroughput)
        ctx.spawn(scene::Effect::Transmission, &TraceStats::transmissionRaysSkipped, ctx.continuation(si, msg, wt, tt, 0.0f), out);
    }
  }
}

}  // namespace pr::rt
