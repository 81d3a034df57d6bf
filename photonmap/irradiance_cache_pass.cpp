// The irradiance cache's pre-pass programs (see irradiance_cache_pass.h).
#include "photonmap/irradiance_cache_pass.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "common/parallel/gather_to_root.h"
#include "common/parallel/runtime.h"
#include "raytrace/integrators/trace_loop.h"

namespace pr::pm {

namespace {

using rt::RayKind;
using rt::RayMessage;

constexpr int kCoarsestStride = 16;
// A record's reach a R_i in pixels at its distance: at least 1.5 (so a stride-1 grid is
// covered between records), at most 24 (so large flat walls still get a record every few
// dozen pixels, bounding the extrapolation by gradients).
constexpr float kMinReachPixels = 1.5f;
constexpr float kMaxReachPixels = 24.0f;
// Gather program: records per row of its virtual image, and per image-space task (a tile).
constexpr int kGatherWidth = 16;
constexpr int kGatherTilePx = 4;
// Probe program: image-space tile edge in pixels.
constexpr int kProbeTilePx = 32;
// Probes or records per task of the coverage and combine stages.
constexpr std::size_t kPerTask = 256;

// A probe: a surface with a diffuse part pixel `pixel`'s camera ray reaches (the first, and
// those beyond mostly transmissive ones), and how far the ray travelled to it (for the
// pixel's footprint there).
struct ProbeHit {
  std::uint32_t pixel = 0;
  std::uint8_t depth = 0;  // surfaces the ray passed before this one: orders a pixel's probes
  rt::SurfaceInteraction si;
  float travelled = 0.0f;
};

// One hit of a gather ray: record slot, ray, bounce, the radiance it adds, and on the first
// hit the distance (NaN on later hits).
struct GatherDeposit {
  std::uint32_t record = 0;
  std::uint16_t ray = 0;
  std::uint8_t bounce = 0;
  glm::vec3 radiance{0.0f};
  float distance = 0.0f;
};

// The random stream of a probe's gather rays: its pixel's, apart for each probe along the
// pixel's ray (a record seen through glass does not repeat the directions of the one in front).
std::uint32_t gatherStream(const ProbeHit& p) { return p.pixel ^ (std::uint32_t(p.depth) << 27); }

template <class T>
struct alignas(64) PerPe {
  std::vector<T> items;
};

// RayMessage as the probe program uses it: bsdfPdf = the distance travelled before this ray.
class ProbeProgram final : public rt::IntegratorBase<ProbeProgram> {
 public:
  ProbeProgram(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
               const rt::IntegratorOptions& options, int maxDepth, bool textures, int pes)
      : IntegratorBase(scene, camera, width, height, options), maxDepth_(maxDepth), textures_(textures), perPe_(std::size_t(pes)) {}

  std::string_view name() const override { return "irradiance-cache probes"; }
  // A probe that leaves the scene finds no surface; it adds nothing (one-pixel film).
  void miss(const RayMessage&, rt::Emit&) const override {}
  // The render's camera rays (sample 0 of one per pixel), counted as the pre-pass's own rays
  // (continuations), not as the render's camera rays.
  void cameraRays(const rt::PixelRect& rect, int, std::vector<RayMessage>& out) const override {
    const std::size_t first = out.size();
    Integrator::cameraRays(rect, 1, out);
    for (std::size_t i = first; i < out.size(); ++i) out[i].kind = RayKind::Continuation;
  }

  void shade(const rt::SurfaceInteraction& si, const RayMessage& msg, rt::Emit& out) const override {
    const scene::Scene& scene = context().scene();
    const float travelled = msg.bsdfPdf + si.t * glm::length(msg.ray.direction);
    rt::ShadingMaterial m = rt::evalMaterial(scene, si, textures_);
    // A surface with a diffuse part gets a probe; one that is mostly glass (a frosted, partly
    // diffuse sphere) also passes the probe on, so the surfaces seen through it - where the
    // eye paths that refract into it arrive - get records too instead of gathering per hit.
    if (rt::maxComponent(m.diffuseColor()) > 0.0f) {
      perPe_[std::size_t(out.pe())].items.push_back({msg.pixel, msg.depth, si, travelled});
      if (m.dielectricWeight() < 0.5f) return;
    }
    if (msg.depth + 1 >= maxDepth_) return;
    // Through ideal mirrors and glass along the dominant branch.
    const rt::ShadingFrame sf(si, m);
    glm::vec3 wi;
    if (m.dielectricWeight() >= 0.5f) {
      const float eta = si.frontFace ? m.ior : 1.0f / m.ior;
      const float cosI = glm::dot(sf.ns, si.wo);
      glm::vec3 wt;
      if (rt::fresnelDielectric(cosI, eta) < 0.5f && rt::refractDirection(si.wo, sf.ns, eta, wt))
        wi = wt;
      else
        wi = glm::normalize(2.0f * cosI * sf.ns - si.wo);
    } else if (m.hasSpecular() && m.deltaSpecular()) {
      wi = sf.frame.toWorld(glm::vec3(-sf.woLocal.x, -sf.woLocal.y, sf.woLocal.z));
    } else {
      return;
    }
    RayMessage next = context().continuation(si, msg, wi, msg.throughput, travelled);
    out.push(next);
  }

  std::vector<PerPe<ProbeHit>>& perPe() const { return perPe_; }

 private:
  int maxDepth_;
  bool textures_;
  mutable std::vector<PerPe<ProbeHit>> perPe_;  // each PE writes its own (Emit::pe)
};

// RayMessage as the gather program uses it: pixel = record slot, sample = ray, depth = bounce.
class GatherProgram final : public rt::IntegratorBase<GatherProgram> {
 public:
  GatherProgram(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                const std::vector<const ProbeHit*>& records, const KdTree& global, const GatherOptions& options, int pes)
      : IntegratorBase(scene, camera, width, height, rt::IntegratorOptions{}),
        records_(records),
        global_(global),
        options_(options),
        strata_(gatherStrata(options.rays)),
        perPe_(std::size_t(pes)) {}

  std::string_view name() const override { return "irradiance-cache gather"; }
  // A gather ray that leaves the scene sees the environment, which is direct light at the
  // record (sampled there by the render): its cell stays dark, its distance infinite.
  void miss(const RayMessage&, rt::Emit&) const override {}

  void cameraRays(const rt::PixelRect& rect, int, std::vector<RayMessage>& out) const override {
    for (int y = rect.y0; y < rect.y1; ++y)
      for (int x = rect.x0; x < rect.x1; ++x) {
        const std::size_t r = std::size_t(y) * std::size_t(context().width()) + std::size_t(x);
        if (r >= records_.size()) return;
        const ProbeHit& p = *records_[r];
        const rt::ShadingFrame sf(p.si);
        for (int j = 0; j < strata_.cells(); ++j) {
          RayMessage m;
          if (!gatherRay(p.si, sf, strata_, gatherStream(p), std::uint32_t(j), options_, m.ray)) continue;
          m.pixel = std::uint32_t(r);
          m.sample = std::uint16_t(j);
          m.depth = 0;
          m.kind = RayKind::Gather;
          out.push_back(m);
        }
      }
  }

  void shade(const rt::SurfaceInteraction& si, const RayMessage& msg, rt::Emit& out) const override {
    thread_local NearestPhotons scratch;
    const std::uint32_t id = gatherStream(*records_[msg.pixel]);
    const GatherInteraction step =
        gatherInteraction(context().scene(), global_, si, msg.ray, msg.throughput, id, msg.sample, msg.depth, options_, scratch);
    const float distance = msg.depth == 0 ? si.t * glm::length(msg.ray.direction) : std::nanf("");
    perPe_[std::size_t(out.pe())].items.push_back({msg.pixel, msg.sample, msg.depth, step.radiance, distance});
    if (!step.continues) return;
    RayMessage next = msg;
    next.ray = step.next;
    next.throughput = step.throughput;
    next.depth = std::uint8_t(msg.depth + 1);
    out.push(next);
  }

  std::vector<PerPe<GatherDeposit>>& perPe() const { return perPe_; }

 private:
  const std::vector<const ProbeHit*>& records_;
  const KdTree& global_;
  GatherOptions options_;
  GatherStrata strata_;
  mutable std::vector<PerPe<GatherDeposit>> perPe_;
};

template <class T>
std::vector<std::vector<T>> takeAll(std::vector<PerPe<T>>& perPe) {
  std::vector<std::vector<T>> out;
  for (PerPe<T>& p : perPe) out.push_back(std::move(p.items));
  return out;
}

}  // namespace

IrradianceCache buildIrradianceCache(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                     const KdTree& global, const CachePassOptions& options, rt::PrePassTracer& tracer,
                                     par::Runtime& rt) {
  IrradianceCache cache(scene.bounds, options.accuracy);
  const int pes = rt.pes();
  const float a = options.accuracy;
  const float pixelAngle =
      camera.projection == scene::Projection::Orthographic ? 0.0f : 2.0f * std::tan(0.5f * camera.yfov) / float(height);
  const float orthoPixel = 2.0f * camera.ymag / float(height);

  // Probes: every pixel's, found where the tracer shades them, sent to PE 0.
  rt::IntegratorOptions probeOptions = options.camera;
  probeOptions.spp = 1;
  const auto probes = std::make_shared<const ProbeProgram>(scene, camera, width, height, probeOptions, options.maxDepth,
                                                           options.gather.textures, pes);
  tracer.trace(probes, kProbeTilePx);
  std::vector<double> probesPerPe(std::size_t(pes), 0.0);
  for (int p = 0; p < pes; ++p) probesPerPe[std::size_t(p)] = double(probes->perPe()[std::size_t(p)].items.size());
  // (Across ranks rank 0 sends them on to every other rank: every rank chooses the same records.)
  std::vector<std::vector<ProbeHit>> found =
      par::gatherToAll(rt, "irradiance-cache probe merge", "probes", par::MessageKind::Data, takeAll(probes->perPe()), sizeof(ProbeHit));
  // Every probe, by pixel and within a pixel in the order its ray met them (one, or more
  // through partly diffuse glass): an order that does not depend on which PE found which.
  // Probes of pixel i: ordered[firstProbe[i] .. firstProbe[i + 1]).
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  std::vector<std::uint32_t> firstProbe(pixels + 1, 0);
  for (const std::vector<ProbeHit>& list : found)
    for (const ProbeHit& h : list) ++firstProbe[std::size_t(h.pixel) + 1];
  for (std::size_t i = 0; i < pixels; ++i) firstProbe[i + 1] += firstProbe[i];
  std::vector<ProbeHit> ordered(firstProbe[pixels]);
  {
    std::vector<std::uint32_t> next(firstProbe.begin(), firstProbe.end() - 1);
    for (std::vector<ProbeHit>& list : found)
      for (ProbeHit& h : list) ordered[next[h.pixel]++] = std::move(h);
  }
  for (std::size_t i = 0; i < pixels; ++i)
    if (firstProbe[i + 1] - firstProbe[i] > 1)
      std::sort(ordered.begin() + firstProbe[i], ordered.begin() + firstProbe[i + 1],
                [](const ProbeHit& a, const ProbeHit& b) { return a.depth < b.depth; });

  std::vector<double> gatherHitsPerPe(std::size_t(pes), 0.0);
  double records = 0.0;
  const GatherStrata strata = gatherStrata(options.gather.rays);
  for (int stride = kCoarsestStride; stride >= 1; stride /= 2) {
    const std::string level = " 1/" + std::to_string(stride);
    // This level's probes, in pixel order: on the stride grid, not on the coarser one.
    std::vector<const ProbeHit*> candidates;
    for (int y = 0; y < height; y += stride)
      for (int x = 0; x < width; x += stride) {
        const bool coarser = stride < kCoarsestStride && x % (2 * stride) == 0 && y % (2 * stride) == 0;
        const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
        if (!coarser)
          for (std::uint32_t k = firstProbe[i]; k < firstProbe[i + 1]; ++k) candidates.push_back(&ordered[k]);
      }
    // Which of them no record of the coarser levels covers (read-only cache, every PE).
    // (Across ranks every rank then holds every flag.)
    std::vector<char> uncovered(candidates.size(), 0);
    par::runStageSharingResults(rt, "irradiance-cache coverage" + level, "irradiance-cache coverage merge" + level, "coverage",
                                uncovered, kPerTask, [&](par::Pe&, par::TaskId t) {
        for (std::size_t i = std::size_t(t) * kPerTask; i < std::min(candidates.size(), std::size_t(t + 1) * kPerTask); ++i) {
          const rt::ShadingFrame sf(candidates[i]->si);
          uncovered[i] = cache.covers(candidates[i]->si.position, sf.ns) ? 0 : 1;
        }
      });
    std::vector<const ProbeHit*> chosen;
    for (std::size_t i = 0; i < candidates.size(); ++i)
      if (uncovered[i]) chosen.push_back(candidates[i]);
    if (chosen.empty()) continue;

    // Their gather rays, traced where the tracer traces them (every PE chose the same probes
    // from the probes and coverage flags broadcast to it); the samples go to PE 0.
    const int gw = std::min<int>(kGatherWidth, int(chosen.size()));
    const int gh = int((chosen.size() + std::size_t(gw) - 1) / std::size_t(gw));
    const auto gather = std::make_shared<const GatherProgram>(scene, camera, gw, gh, chosen, global, options.gather, pes);
    tracer.trace(gather, kGatherTilePx);
    for (int p = 0; p < pes; ++p) gatherHitsPerPe[std::size_t(p)] += double(gather->perPe()[std::size_t(p)].items.size());
    std::vector<std::vector<GatherDeposit>> samples = par::gatherToAll(
        rt, "irradiance-cache gather merge" + level, "gather samples", par::MessageKind::Data, takeAll(gather->perPe()),
        sizeof(GatherDeposit));
    std::vector<GatherDeposit> all;
    for (std::vector<GatherDeposit>& s : samples) all.insert(all.end(), s.begin(), s.end());
    std::sort(all.begin(), all.end(), [](const GatherDeposit& x, const GatherDeposit& y) {
      return x.record != y.record ? x.record < y.record : x.ray != y.ray ? x.ray < y.ray : x.bounce < y.bounce;
    });
    std::vector<GatherCell> cells(chosen.size() * std::size_t(strata.cells()));
    for (const GatherDeposit& d : all) {
      GatherCell& c = cells[std::size_t(d.record) * std::size_t(strata.cells()) + d.ray];
      c.radiance += d.radiance;
      if (d.bounce == 0) c.distance = d.distance;
    }

    // The records, computed in parallel, inserted in pixel order.
    // (Across ranks every rank then holds every record.)
    std::vector<IrradianceRecord> made(chosen.size());
    par::runStageSharingResults(rt, "irradiance-cache records" + level, "irradiance-cache records merge" + level, "records",
                                made, kPerTask, [&](par::Pe&, par::TaskId t) {
      for (std::size_t i = std::size_t(t) * kPerTask; i < std::min(chosen.size(), std::size_t(t + 1) * kPerTask); ++i) {
        const ProbeHit& p = *chosen[i];
        const rt::ShadingFrame sf(p.si);
        IrradianceRecord r = combineGather(
            p.si, sf, strata, gatherStream(p), options.gather,
            std::span<const GatherCell>(cells.data() + i * std::size_t(strata.cells()), std::size_t(strata.cells())));
        // The translation-gradient limit (Krivanek et al. 2006): the extrapolation by the
        // gradient may not halve the irradiance within the radius; then the screen clamps.
        const glm::vec3 g = 0.2126f * r.translationGradient[0] + 0.7152f * r.translationGradient[1] +
                            0.0722f * r.translationGradient[2];
        const float e = rt::luminance(r.irradiance), gl = glm::length(g);
        if (gl > 0.0f && e > 0.0f) r.radius = std::min(r.radius, e / gl);
        const float footprint = pixelAngle > 0.0f ? p.travelled * pixelAngle : orthoPixel;
        r.radius = std::clamp(r.radius, kMinReachPixels * footprint / a, kMaxReachPixels * footprint / a);
        made[i] = r;
      }
    });
    // The new records reached every PE (the records merge's broadcast), where every rank's
    // controlling thread inserts them for the next level's coverage and the render.
    for (const IrradianceRecord& r : made) cache.insert(r);
    records += double(made.size());
  }
  for (int p = 0; p < pes; ++p) {
    rt.addCounter("IrradianceCache/probes", p, probesPerPe[std::size_t(p)]);
    rt.addCounter("IrradianceCache/gather_hits", p, gatherHitsPerPe[std::size_t(p)]);
  }
  rt.addCounter("IrradianceCache/records", 0, records);
  return cache;
}

}  // namespace pr::pm
