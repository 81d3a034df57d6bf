// The photon-map integrator (see photon_map_integrator.h): the pre-pass that traces the maps
// and places the irradiance-cache records, and the shading of one hit.
//
// The pre-pass runs as programs through the render's tracer (photon_pass.h for the maps,
// irradiance_cache_pass.h for the cache, whose record placement is deterministic).
#include "photonmap/photon_map_integrator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/util/error.h"
#include "photonmap/final_gather.h"
#include "photonmap/irradiance_cache_pass.h"
#include "photonmap/photon_pass.h"
#include "raytrace/core/bvh.h"

namespace pr::pm {

namespace {

using rt::kPi;
using rt::RayKind;
using rt::RayMessage;

// Rays weaker than this add nothing visible (below 1/4096 of a camera ray's weight).
constexpr float kMinThroughput = 1.0f / 4096.0f;
// Random dimensions of this integrator at a vertex: fallback gather rays, glossy rays, the
// choice whether a secondary hit reads its map's glossy part (mapRadiance's roulette), rays
// through frosted glass.
constexpr std::uint32_t kGatherDim = rt::Dim::kIntegratorOwn;
constexpr std::uint32_t kGlossyDim = rt::Dim::kIntegratorOwn + 512;
constexpr std::uint32_t kMapReadDim = rt::Dim::kIntegratorOwn + 512 + 3 * 256;
constexpr std::uint32_t kDielectricDim = kMapReadDim + 1;  // 3 per frosted-glass ray
constexpr int kMaxRaysPerVertex = 256;
// Photons per map at most (CLI range; the photon program's pixel index is 32 bits).
constexpr std::size_t kMaxPhotons = 100000000;
// The caustic and indirect estimates are read on a kSmoothGrid x kSmoothGrid sub-grid of a
// pixel's sample strata (when its strata allow): 4 of 64 samples, weighted 16 each.
constexpr int kSmoothGrid = 2;

float sceneDiagonal(const scene::Scene& scene) {
  scene::Bounds b = scene.bounds;
  if (b.empty())
    for (const glm::vec3& p : scene.positions) b.extend(p);
  return std::max(glm::length(b.extent()), 1.0e-6f);
}

}  // namespace

std::string_view toString(PhotonView view) {
  switch (view) {
    case PhotonView::GlobalMap: return "global-map";
    case PhotonView::CausticMap: return "caustic-map";
    default: return "full";
  }
}

PhotonView parsePhotonView(std::string_view text) {
  for (PhotonView v : {PhotonView::Full, PhotonView::GlobalMap, PhotonView::CausticMap})
    if (text == toString(v)) return v;
  throw InputError("unknown --view '" + std::string(text) + "'; expected full, global-map or caustic-map");
}

PhotonMapIntegrator::PhotonMapIntegrator(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                         const rt::IntegratorOptions& options, const PhotonMapSettings& settings)
    : IntegratorBase(scene, camera, width, height, options),
      settings_(settings),
      camera_(camera),
      state_(std::make_unique<State>()) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw InputError("photonmap: " + what);
  };
  check(settings.globalK >= 1 && settings.globalK <= 10000, "--k must be in [1, 10000]");
  check(settings.causticK >= 1 && settings.causticK <= 10000, "--caustic-k must be in [1, 10000]");
  check(settings.globalRadius >= 0.0f && std::isfinite(settings.globalRadius), "--radius must be >= 0 (0 = automatic)");
  check(settings.causticRadius >= 0.0f && std::isfinite(settings.causticRadius), "--caustic-radius must be >= 0 (0 = automatic)");
  check(settings.gatherRays >= 1 && settings.gatherRays <= 65536, "--gather must be in [1, 65536]");
  check(settings.globalPhotons <= kMaxPhotons && settings.causticPhotons <= kMaxPhotons,
        "--photons and --caustic-photons must be at most 100000000 each");
  check(settings.cacheAccuracy > 0.0f && settings.cacheAccuracy <= 1.0f, "--cache-accuracy must be in (0, 1]");
  check(settings.fallbackGatherRays >= 1 && settings.fallbackGatherRays <= kMaxRaysPerVertex, "fallback gather rays out of range");
  check(settings.maxGlossyRays >= 1 && settings.maxGlossyRays <= kMaxRaysPerVertex, "glossy rays out of range");
  check(settings.areaLightSamples >= 1 && settings.areaLightSamples <= 64, "area-light samples must be in [1, 64]");
  const float diagonal = sceneDiagonal(scene);
  globalDensity_.k = settings.globalK;
  globalDensity_.maxRadius = settings.globalRadius > 0.0f ? settings.globalRadius : kAutoGlobalRadius * diagonal;
  globalDensity_.filter = DensityFilter::Box;
  causticDensity_.k = settings.causticK;
  causticDensity_.maxRadius = settings.causticRadius > 0.0f ? settings.causticRadius : kAutoCausticRadius * diagonal;
  causticDensity_.filter = DensityFilter::Cone;
  state_->cache = IrradianceCache(scene.bounds, settings.cacheAccuracy);
  // Shadow rays per pixel: at least areaLightSamples in all, spread over the pixel's samples.
  areaSamples_ = std::max(1, (settings.areaLightSamples + options.spp - 1) / options.spp);
  // The smooth terms' samples: a regular sub-grid of the pixel's strata, up to kSmoothGrid x
  // kSmoothGrid of them, each the centre stratum of its block of strata.
  const glm::ivec2 strata = rt::strataFor(options.spp);
  auto divisorUpTo = [](int n, int cap) {
    int d = std::min(n, cap);
    while (d > 1 && n % d != 0) --d;
    return std::max(1, d);
  };
  smoothBlock_ = glm::ivec2(strata.x / divisorUpTo(strata.x, kSmoothGrid), strata.y / divisorUpTo(strata.y, kSmoothGrid));
  smoothStrataX_ = strata.x;
}

float PhotonMapIntegrator::smoothWeight(std::uint16_t sample) const {
  const int sx = int(sample) % smoothStrataX_, sy = int(sample) / smoothStrataX_;
  if (sx % smoothBlock_.x != smoothBlock_.x / 2 || sy % smoothBlock_.y != smoothBlock_.y / 2) return 0.0f;
  return float(smoothBlock_.x * smoothBlock_.y);
}

// ---- pre-pass ---------------------------------------------------------------------------------

void PhotonMapIntegrator::prePass(rt::PrePassTracer& tracer, par::Runtime& rt) const {
  const rt::IntegratorContext& ctx = context();
  PhotonOptions photons;
  photons.seed = options().seed;
  photons.globalPhotons = settings_.globalPhotons;
  photons.causticPhotons = settings_.causticPhotons;
  photons.batchSize = settings_.photonBatch;
  photons.textures = ctx.simulates(scene::Effect::Textures);
  photons.effects = options().effects;
  // A view traces only the map it shows, whatever the plan says of its effect.
  if (settings_.view != PhotonView::Full) {
    photons.effects.set(scene::Effect::IndirectDiffuse, settings_.view == PhotonView::GlobalMap);
    photons.effects.set(scene::Effect::Caustics, settings_.view == PhotonView::CausticMap);
  }
  // Pass 1 through the render's tracer; the maps are built from the merged photons.
  PhotonLists lists = tracePhotonMessages(ctx.scene(), camera_, photons, tracer, rt);
  state_->maps.stats = lists.stats;
  // Whether any global photon came along glossy bounces without a diffuse one: only then is
  // the glossy-caustic term read at eye points (a search that finds nothing still costs).
  const PhotonSelection glossyOnly{PhotonPath::kGlossy, PhotonPath::kDiffuse};
  state_->glossyCaustics = std::any_of(lists.global.begin(), lists.global.end(), [&](const Photon& p) { return glossyOnly.accepts(p); });
  state_->maps.global = KdTree::build(lists.global, rt);
  state_->maps.caustic = KdTree::build(std::move(lists.caustic), rt);
  state_->irradiance = PrecomputedIrradiance();
  if (settings_.view == PhotonView::Full && settings_.irradianceStride > 0 && !state_->maps.global.empty())
    state_->irradiance = PrecomputedIrradiance::build(lists.global, lists.globalNormals, state_->maps.global,
                                                      globalDensity_, settings_.irradianceStride, rt);
  // Every PE reads both maps and the precomputed points, which every rank built from the
  // photons and points broadcast to every PE (booked there, gatherToAll): a replicated
  // computation, no further transfer.

  state_->cache = IrradianceCache(ctx.scene().bounds, settings_.cacheAccuracy);
  if (settings_.view == PhotonView::Full && ctx.simulates(scene::Effect::IndirectDiffuse) && !state_->maps.global.empty()) {
    CachePassOptions cache;
    cache.gather.rays = settings_.gatherRays;
    cache.gather.global = globalDensity_;
    cache.gather.precomputed = &state_->irradiance;
    cache.gather.textures = ctx.simulates(scene::Effect::Textures);
    cache.gather.seed = options().seed;
    // A mirror or refraction after the gathering point's diffuse bounce is a caustic path: with
    // the plan's caustics off, gather rays end at ideal specular surfaces, as the path tracer's do.
    if (!ctx.simulates(scene::Effect::Caustics)) cache.gather.specularBounces = 0;
    cache.accuracy = settings_.cacheAccuracy;
    cache.maxDepth = options().maxDepth;
    cache.camera = options();
    // (The cache pass broadcasts each level's records as it makes them.)
    state_->cache = buildIrradianceCache(ctx.scene(), camera_, ctx.width(), ctx.height(), state_->maps.global, cache, tracer, rt);
  }
}

// ---- shading ----------------------------------------------------------------------------------

void PhotonMapIntegrator::shade(const rt::SurfaceInteraction& si, const RayMessage& incoming, rt::Emit& out) const {
  const rt::IntegratorContext& ctx = context();
  const State& state = *state_;
  rt::ShadingMaterial m = ctx.material(si, out);
  const RayMessage msg = ctx.arrived(si, m, incoming);

  const rt::ShadingFrame sf(si, m);
  thread_local NearestPhotons scratch;
  if (settings_.view != PhotonView::Full) {
    const bool global = settings_.view == PhotonView::GlobalMap;
    out.addRadiance(msg.pixel, msg.throughput * mapRadiance(m, sf, global ? state.maps.global : state.maps.caustic, nullptr,
                                                            si, global ? globalDensity_ : causticDensity_, scratch));
    return;
  }

  const float dielectric = m.dielectricWeight();
  const float opaque = 1.0f - dielectric;
  // One of `of` rays that share a weight: the cut-off applies to their sum, not to each.
  auto spawn = [&](scene::Effect effect, std::uint64_t rt::TraceStats::*skipped, RayMessage ray, int of = 1) {
    if (rt::maxComponent(ray.throughput) * float(of) > kMinThroughput && rt::isFinite(ray.throughput))
      ctx.spawn(effect, skipped, ray, out);
  };
  auto mirror = [&]() { return sf.frame.toWorld(glm::vec3(-sf.woLocal.x, -sf.woLocal.y, sf.woLocal.z)); };

  // A gathering or glossy ray's hit: all of its light from the global map (no emission, which
  // light sampling at the ray's origin already counted); both go on through ideal specular
  // surfaces to the diffuse surface behind them, as the cache's gathering does, keeping their
  // kind (a glossy ray its bsdfPdf > 0 mark).
  const bool secondary = msg.kind == RayKind::Gather || (msg.kind == RayKind::Continuation && msg.bsdfPdf > 0.0f);
  if (secondary) {
    out.addRadiance(msg.pixel, msg.throughput * mapRadiance(m, sf, state.maps.global, &state.irradiance, si, globalDensity_,
                                                            scratch, MapRead::Secondary, ctx.sample(msg, kMapReadDim)));
    if (msg.depth >= options().maxDepth) return;
    glm::vec3 wi, factor;
    if (!specularBounce(m, si, sf, ctx.sample(msg, rt::Dim::kLobe), ctx.sample(msg, rt::Dim::kBsdfU),
                        ctx.sample(msg, rt::Dim::kBsdfV), wi, factor))
      return;
    // After the diffuse or glossy bounce that made this ray: a caustic path (as in the cache pass).
    if (!ctx.simulates(scene::Effect::Caustics)) {
      ++out.stats().causticRaysSkipped;
      return;
    }
    RayMessage next = ctx.continuation(si, msg, wi, msg.throughput * factor, msg.kind == RayKind::Gather ? 0.0f : msg.bsdfPdf);
    next.kind = msg.kind;
    if (msg.kind == RayKind::Gather)
      spawn(scene::Effect::IndirectDiffuse, &rt::TraceStats::indirectRaysSkipped, next);
    else
      spawn(scene::Effect::GlossySpecular, &rt::TraceStats::glossyRaysSkipped, next);
    return;
  }

  // An eye path (camera ray, or ideal specular and refraction rays from one): emission in full.
  const glm::vec3 le = ctx.emitted(m, si, out);
  if (rt::maxComponent(le) > 0.0f) out.addRadiance(msg.pixel, msg.throughput * le);
  if (msg.depth >= options().maxDepth) return;
  ctx.directLight(si, m, sf.frame, sf.woLocal, msg, opaque, false, out, areaSamples_);

  // Caustics and indirect light are smooth over many pixels, so read by a stratified subset of
  // the pixel's samples only. Caustics from the caustic map with the full non-delta BRDF (the
  // layers and the glossy lobe too: light focused by a mirror seen in a glossy floor); glossy
  // caustics - light that came along glossy bounces but no diffuse one, which gather rays
  // leave out - from the global map where they land.
  const float smooth = smoothWeight(msg.sample);
  if (smooth > 0.0f && m.hasNonDeltaPart()) {
    if (!ctx.simulates(scene::Effect::Caustics))
      ++out.stats().causticRaysSkipped;
    else if (!state.maps.caustic.empty())
      out.addRadiance(msg.pixel, msg.throughput * smooth * mapRadiance(m, sf, state.maps.caustic, nullptr, si, causticDensity_, scratch));
    if (state.glossyCaustics)
      out.addRadiance(msg.pixel, msg.throughput * smooth * mapRadiance(m, sf, state.maps.global, nullptr, si, globalDensity_,
                                                                       scratch, MapRead::GlossyCaustic));
  }
  // Indirect light on the diffuse base (under its layers) from the cache.
  const glm::vec3 diffuse = m.diffuseColor() * (smooth * rt::diffuseLayerScale(m, sf.woLocal));
  if (rt::maxComponent(diffuse) > 0.0f) {
    glm::vec3 irradiance;
    if (!ctx.simulates(scene::Effect::IndirectDiffuse)) {
      ++out.stats().indirectRaysSkipped;
    } else if (state.cache.lookup(si.position, sf.ns, irradiance)) {
      out.addRadiance(msg.pixel, msg.throughput * lambertianRadiance(diffuse, irradiance));
    } else if (!state.maps.global.empty()) {
      // No record here (a point seen only through a mirror, or between the probes): gather
      // with rays that travel as messages, cosine-distributed so each carries diffuse / n.
      const int n = settings_.fallbackGatherRays;
      for (int i = 0; i < n; ++i) {
        const glm::vec3 wi = sf.frame.toWorld(rt::cosineHemisphere(ctx.sample(msg, kGatherDim + 2u * std::uint32_t(i)),
                                                                    ctx.sample(msg, kGatherDim + 2u * std::uint32_t(i) + 1u)));
        if (glm::dot(wi, sf.ng) <= 0.0f) continue;
        RayMessage g = ctx.continuation(si, msg, wi, msg.throughput * diffuse / float(n), 0.0f);
        g.kind = RayKind::Gather;
        spawn(scene::Effect::IndirectDiffuse, &rt::TraceStats::indirectRaysSkipped, g, n);
      }
    }
  }

  // An ideal mirror base: one ray, under the coat's share.
  if (opaque > 0.0f && m.hasSpecular() && m.deltaSpecular() && glm::dot(mirror(), sf.ng) > 0.0f)
    spawn(scene::Effect::IdealSpecular, &rt::TraceStats::specularRaysSkipped,
          ctx.continuation(si, msg, mirror(),
                           msg.throughput * m.specularFresnel(sf.woLocal.z) * rt::baseLayerWeight(m, sf.woLocal), 0.0f));
  // The other non-Lambertian lobes (a rough specular lobe, sheen, clear coat): Monte Carlo
  // glossy rays whose hits read the global map, more the rougher the lobes and the larger their
  // share of the reflectance - a dielectric's 4 % layer over a diffuse base gets one - and one
  // below the first hit.
  if (opaque > 0.0f && rt::hasNonLambertian(m)) {
    float spread = 0.0f;
    if (m.hasSpecular() && !m.deltaSpecular()) spread = m.roughness * rt::specularProbability(m, sf.woLocal.z);
    if (m.hasClearcoat()) spread = std::max(spread, m.clearcoatRoughness * rt::coatProbability(m, sf.woLocal));
    if (m.hasSheen()) spread = std::max(spread, m.sheenRoughness * rt::maxComponent(m.sheenColor));
    const int n = msg.depth == 0 ? std::max(1, int(std::ceil(float(settings_.maxGlossyRays) * spread))) : 1;
    for (int i = 0; i < n; ++i) {
      const std::uint32_t dim = kGlossyDim + 3u * std::uint32_t(i);
      const rt::BsdfSample s = rt::sampleNonLambertian(m, sf.woLocal, ctx.sample(msg, dim), ctx.sample(msg, dim + 1u),
                                                       ctx.sample(msg, dim + 2u));
      if (!s.valid) continue;
      const glm::vec3 wi = sf.frame.toWorld(s.wi);
      if (glm::dot(wi, sf.ng) <= 0.0f) continue;
      // bsdfPdf > 0 marks the ray as glossy: its hit reads the global map.
      spawn(scene::Effect::GlossySpecular, &rt::TraceStats::glossyRaysSkipped,
            ctx.continuation(si, msg, wi, msg.throughput * s.weight / float(n), std::max(s.pdf, 1.0e-30f)), n);
    }
  }

  // The smooth dielectric: Fresnel reflection and refraction, one ray each (as Whitted).
  // Frosted glass: eye paths through it about sampled microfacet normals (Fresnel choosing
  // reflection or refraction), more the rougher it is, one below the first hit; they stay eye
  // paths, lit at their next hit as the eye's own, since light sampling never covers this part.
  if (dielectric > 0.0f && !m.deltaSpecular()) {
    const int n = msg.depth == 0 ? std::max(1, int(std::ceil(float(settings_.maxGlossyRays) * m.roughness))) : 1;
    for (int i = 0; i < n; ++i) {
      const std::uint32_t dim = kDielectricDim + 3u * std::uint32_t(i);
      const rt::DielectricSample d =
          rt::sampleDielectric(m, si, sf, ctx.sample(msg, dim), ctx.sample(msg, dim + 1u), ctx.sample(msg, dim + 2u));
      if (d.valid)
        spawn(scene::Effect::Transmission, &rt::TraceStats::transmissionRaysSkipped,
              ctx.continuation(si, msg, d.wi, msg.throughput * d.weight * (dielectric / float(n)), 0.0f), n);
    }
  } else if (dielectric > 0.0f) {
    const float eta = si.frontFace ? m.ior : 1.0f / m.ior;
    const float cosI = glm::dot(sf.ns, si.wo);
    const float fr = rt::fresnelDielectric(cosI, eta);
    spawn(scene::Effect::Transmission, &rt::TraceStats::transmissionRaysSkipped,
          ctx.continuation(si, msg, glm::normalize(2.0f * cosI * sf.ns - si.wo), msg.throughput * (dielectric * fr), 0.0f));
    glm::vec3 wt;
    if (fr < 1.0f && rt::refractDirection(si.wo, sf.ns, eta, wt))
      spawn(scene::Effect::Transmission, &rt::TraceStats::transmissionRaysSkipped,
            ctx.continuation(si, msg, wt,
                             msg.throughput * m.transmissionTint(si.frontFace) *
                                 (dielectric * (1.0f - fr) * m.refractedRadianceScale(si.frontFace)),
                             0.0f));
  }
}

rt::IntegratorInfo photonMapIntegratorEntry(const PhotonMapSettings& settings) {
  return {"photonmap",
          "Jensen's two-pass photon map: direct light by shadow rays, caustics from the caustic map, indirect "
          "diffuse by final gathering over the global map through an irradiance cache",
          [settings](const rt::IntegratorSetup& s) -> std::shared_ptr<const rt::Integrator> {
            return std::make_shared<const PhotonMapIntegrator>(s.scene, s.camera, s.width, s.height, s.options, settings);
          }};
}

}  // namespace pr::pm
