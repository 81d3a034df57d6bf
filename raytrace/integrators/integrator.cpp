// What the Whitted and path-tracing integrators share (see integrator.h): camera rays,
// the shading frame, next-event estimation and continuation rays. Runs on whichever PE holds
// a message; reads the Scene and light sampler only, writes the Film through Emit.
#include "raytrace/integrators/integrator.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/util/error.h"

namespace pr::rt {

std::string_view toString(IntegratorKind kind) { return kind == IntegratorKind::Whitted ? "whitted" : "path"; }

IntegratorContext::IntegratorContext(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                     const IntegratorOptions& options)
    : scene_(&scene), camera_(camera), width_(width), height_(height), options_(options), lights_(scene, options.effects.has(scene::Effect::Textures)) {
  PR_CHECK(width > 0 && height > 0, "image size must be positive");
  PR_CHECK(options.spp >= 1 && options.spp <= kMaxSpp, "spp out of range: " + std::to_string(options.spp));
  PR_CHECK(options.maxDepth >= 1 && options.maxDepth <= kMaxDepthLimit,
           "max depth out of range: " + std::to_string(options.maxDepth));
}

ShadingFrame::ShadingFrame(const SurfaceInteraction& si) : ShadingFrame(si, si.shadingNormal) {}

ShadingFrame::ShadingFrame(const SurfaceInteraction& si, ShadingMaterial& m) : ShadingFrame(si, m.normal) {
  if (m.anisotropy > 0.0f) {
    // The local x axis along the anisotropy direction: the uv tangent turned by it in the
    // tangent plane, so the BSDF's anisotropic lobe reads (x, y) as (along, across).
    const glm::vec3 n = frame.n;
    glm::vec3 t = glm::vec3(si.tangent) - n * glm::dot(n, glm::vec3(si.tangent));
    if (glm::dot(t, t) > 1.0e-12f) {
      t = glm::normalize(t);
      const glm::vec3 b = glm::cross(n, t);
      const glm::vec3 s = glm::normalize(m.anisotropyDirection.x * t + m.anisotropyDirection.y * b);
      frame.s = s;
      frame.t = glm::cross(n, s);
      woLocal = frame.toLocal(si.wo);
      woLocal.z = std::max(woLocal.z, 1.0e-6f);
    } else {
      m.anisotropy = 0.0f;  // no direction to be anisotropic along
    }
  }
  if (!m.hasClearcoat()) return;
  const glm::vec3 coat = si.frontFace ? m.clearcoatNormalWorld : -m.clearcoatNormalWorld;
  m.clearcoatNormal = glm::dot(coat, si.wo) > 1.0e-6f ? frame.toLocal(coat) : glm::vec3(0.0f, 0.0f, 1.0f);
}

ShadingFrame::ShadingFrame(const SurfaceInteraction& si, const glm::vec3& shadingNormal)
    : ng(si.frontFace ? si.geometricNormal : -si.geometricNormal),
      ns(si.frontFace ? shadingNormal : -shadingNormal),
      frame(ns),
      woLocal(0.0f) {
  // Interpolated normals can put wo below the shading hemisphere at silhouettes; the
  // geometric normal is then the only frame in which wo is above the surface.
  if (glm::dot(ns, si.wo) <= 1.0e-6f) {
    ns = ng;
    frame = Frame(ng);
  }
  woLocal = frame.toLocal(si.wo);
  woLocal.z = std::max(woLocal.z, 1.0e-6f);  // wo lies in the upper hemisphere by construction
}

DielectricSample sampleDielectric(const ShadingMaterial& m, const SurfaceInteraction& si, const ShadingFrame& sf, float choice,
                                  float u, float v, Transport transport) {
  DielectricSample s;
  const float eta = si.frontFace ? m.ior : 1.0f / m.ior;
  s.delta = m.deltaSpecular();
  glm::vec3 n = sf.ns;
  if (!s.delta) {
    n = sf.frame.toWorld(sampleMicrofacetNormal(m, u, v));
    if (glm::dot(n, si.wo) <= 0.0f) return s;
  }
  const float cosI = glm::dot(n, si.wo);
  glm::vec3 wt;
  s.reflected = choice < fresnelDielectric(cosI, eta) || !refractDirection(si.wo, n, eta, wt);
  s.wi = s.reflected ? glm::normalize(2.0f * cosI * n - si.wo) : wt;
  float weight = 1.0f;
  if (!s.delta) {
    // Reflection stays on the side it came from, refraction crosses the geometric surface.
    if ((glm::dot(s.wi, sf.ng) > 0.0f) != s.reflected) return s;
    weight = microfacetWeight(m, sf.woLocal, sf.frame.toLocal(s.wi), sf.frame.toLocal(n));
  }
  if (!s.reflected && transport == Transport::Radiance) weight *= m.refractedRadianceScale(si.frontFace);
  s.weight = s.reflected ? glm::vec3(weight) : weight * m.transmissionTint(si.frontFace);
  s.valid = maxComponent(s.weight) > 0.0f && isFinite(s.weight);
  return s;
}

ShadingMaterial IntegratorContext::material(const SurfaceInteraction& si, Emit& out) const {
  const bool textures = simulates(scene::Effect::Textures);
  if (!textures && usesTextures(scene_->materials[si.material])) ++out.stats().textureEvaluationsSkipped;
  ShadingMaterial m = evalMaterial(*scene_, si, textures);
  if (!simulates(scene::Effect::Anisotropy)) m.anisotropy = 0.0f;  // the plan's isotropic stand-in
  return m;
}

glm::vec3 IntegratorContext::emitted(const ShadingMaterial& m, const SurfaceInteraction& si, Emit& out) const {
  const glm::vec3 le = emittedRadiance(m, si);
  if (simulates(scene::Effect::Emission) || !(maxComponent(le) > 0.0f)) return le;
  ++out.stats().emissionSkipped;
  return glm::vec3(0.0f);
}

void IntegratorContext::directLight(const SurfaceInteraction& si, const ShadingMaterial& m, const Frame& frame,
                                    const glm::vec3& woLocal, const RayMessage& msg, float opaqueProbability, bool mis,
                                    Emit& out, int areaSamples, const OpaqueEval* eval) const {
  // Clear glass (opaque lobes never picked, and none with a weight): no light to sample.
  if (!(opaqueProbability > 0.0f)) return;
  const bool area = lights_.hasAreaLights();
  if (!simulates(scene::Effect::DirectLight)) {
    out.stats().lightSamplesSkipped += scene_->lights.size() + (area ? uint64_t(std::max(1, areaSamples)) : 0u) +
                                       (scene_->environment ? 1u : 0u);
    return;
  }
  const bool shadows = simulates(scene::Effect::Shadows);
  // Light from behind the geometric surface cannot reach an opaque side (no leaks through
  // thin walls whose interpolated normal leans towards the light).
  const glm::vec3 ng = si.frontFace ? si.geometricNormal : -si.geometricNormal;
  auto addSample = [&](const LightSample& ls, float scale) {
    if (glm::dot(ls.wi, ng) <= 0.0f) return;
    const glm::vec3 wiLocal = frame.toLocal(ls.wi);
    if (wiLocal.z <= 0.0f) return;
    const glm::vec3 f = eval ? (*eval)(woLocal, wiLocal) : evalOpaque(m, woLocal, wiLocal);
    float weight = 1.0f;
    if (mis && !eval && ls.pdf > 0.0f) {
      // Power heuristic (Veach 1997, eq. 9.13) against the BSDF sample that could hit this light.
      const float pb = opaqueProbability * pdfOpaque(m, woLocal, wiLocal);
      weight = ls.pdf * ls.pdf / (ls.pdf * ls.pdf + pb * pb);
    }
    const glm::vec3 c = msg.throughput * f * ls.radiance * (wiLocal.z * weight * scale);
    if (!(maxComponent(c) > 0.0f) || !isFinite(c)) return;
    RayMessage shadow;
    shadow.ray = ls.shadowRay;
    shadow.throughput = c;
    shadow.pixel = msg.pixel;
    shadow.sample = msg.sample;
    shadow.depth = msg.depth;
    shadow.kind = RayKind::Shadow;
    if (shadows) {
      out.push(shadow);
    } else {
      ++out.stats().shadowTestsSkipped;
      out.addRadiance(shadow.pixel, shadow.throughput);  // what Integrator::miss adds for it
    }
  };
  LightSample ls;
  for (const scene::PunctualLight& light : scene_->lights)
    if (lights_.samplePunctual(light, si, ls)) addSample(ls, 1.0f);
  // The environment: one sample by its own distribution, or - a uniform one, where no BSDF
  // sample is weighed against it (no MIS) - cosine-distributed about the surface, which leaves
  // an unoccluded diffuse point no variance at all. The shadow ray runs to infinity.
  if (const scene::Environment* env = scene_->environment.get()) {
    float pdf = 0.0f;
    glm::vec3 dir;
    if (!mis && env->isUniform()) {
      const glm::vec3 local = cosineHemisphere(sample(msg, Dim::kEnvU), sample(msg, Dim::kEnvV));
      dir = Frame(ng).toWorld(local);
      pdf = local.z * kInvPi;
    } else {
      dir = env->sample(sample(msg, Dim::kEnvU), sample(msg, Dim::kEnvV), pdf);
    }
    if (pdf > 0.0f && std::isfinite(pdf)) {
      LightSample es;
      es.wi = dir;
      es.pdf = pdf;
      es.radiance = env->radiance(dir) / pdf;
      es.shadowRay = spawnRay(si, dir);
      addSample(es, 1.0f);
    }
  }
  if (!area) return;
  const int n = std::max(1, areaSamples);
  if (!simulates(scene::Effect::Emission)) {
    out.stats().lightSamplesSkipped += uint64_t(n);
    return;
  }
  for (int i = 0; i < n; ++i) {
    const uint32_t d = i == 0 ? Dim::kLightPick : Dim::kLightExtra + 3u * uint32_t(i - 1);
    const uint32_t du = i == 0 ? Dim::kLightU : d + 1u, dv = i == 0 ? Dim::kLightV : d + 2u;
    if (lights_.sampleArea(si, sample(msg, d), sample(msg, du), sample(msg, dv), ls)) addSample(ls, 1.0f / float(n));
  }
}

RayMessage IntegratorContext::continuation(const SurfaceInteraction& si, const RayMessage& msg, const glm::vec3& wi,
                                           const glm::vec3& throughput, float bsdfPdf) const {
  RayMessage next;
  next.ray = spawnRay(si, wi);
  next.throughput = throughput;
  next.pixel = msg.pixel;
  next.sample = msg.sample;
  next.depth = uint8_t(msg.depth + 1);
  next.kind = RayKind::Continuation;
  next.bsdfPdf = bsdfPdf;
  return next;
}

Integrator::Integrator(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                       const IntegratorOptions& options)
    : ctx_(scene, camera, width, height, options), camera_(camera) {}

void Integrator::cameraRays(const PixelRect& rect, int spp, std::vector<RayMessage>& out) const {
  PR_CHECK(spp >= 1 && spp <= kMaxSpp, "spp out of range: " + std::to_string(spp));
  const int w = ctx_.width(), h = ctx_.height();
  const float aspect = float(w) / float(h);
  const glm::mat3 rotation(camera_.cameraToWorld);
  const glm::vec3 eye = camera_.position();
  const float tanY = std::tan(0.5f * camera_.yfov);
  out.reserve(out.size() + size_t(rect.pixels()) * size_t(spp));
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      RayMessage m;
      m.pixel = uint32_t(y) * uint32_t(w) + uint32_t(x);
      m.kind = RayKind::Camera;
      for (int s = 0; s < spp; ++s) {
        m.sample = uint16_t(s);
        const glm::vec2 j = stratifiedPixelSample(s, spp, ctx_.sample(m, Dim::kPixelX), ctx_.sample(m, Dim::kPixelY));
        // Film position in [-1, 1]^2, +y up (row 0 is the top of the picture).
        const float sx = 2.0f * (float(x) + j.x) / float(w) - 1.0f;
        const float sy = 1.0f - 2.0f * (float(y) + j.y) / float(h);
        if (camera_.projection == scene::Projection::Orthographic) {
          // The image aspect wins: ymag is kept, x widened (camera.h).
          const glm::vec3 local(sx * camera_.ymag * aspect, sy * camera_.ymag, 0.0f);
          m.ray = Ray{eye + rotation * local, 0.0f, glm::normalize(rotation * glm::vec3(0.0f, 0.0f, -1.0f)), kInfinity};
        } else {
          const glm::vec3 local(sx * tanY * aspect, sy * tanY, -1.0f);
          m.ray = Ray{eye, 0.0f, glm::normalize(rotation * local), kInfinity};
        }
        out.push_back(m);
      }
    }
  }
}

}  // namespace pr::rt
