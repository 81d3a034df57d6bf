// Final gathering into an irradiance-cache record (see final_gather.h). The gradient formulas
// are Ward and Heckbert, "Irradiance Gradients" (1992): the rotation gradient from each cell's
// direction, the translation gradient from the walls between neighbouring cells.
#include "photonmap/final_gather.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "raytrace/core/bvh.h"
#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/sampling.h"

namespace pr::pm {

namespace {

using rt::kPi;

// Streams of sample1D(seed ^ kGatherSalt, record, ray, bounce, dim), apart from the camera
// paths' (seed, pixel, sample, depth, dim).
constexpr std::uint64_t kGatherSalt = 0x6761746865720000ull;  // "gather"
constexpr std::uint32_t kThetaDim = 0, kPhiDim = 1, kBranchDim = 2, kGlossyDim = 3, kMicrofacetUDim = 4, kMicrofacetVDim = 5;
constexpr std::uint32_t kDirectionDepth = 255;

// The jittered (sin^2 theta, phi) of ray j.
void cellAngles(GatherStrata strata, std::uint32_t id, std::uint32_t j, std::uint64_t seed, float& sin2, float& phi) {
  const int jj = int(j) / strata.n, k = int(j) % strata.n;
  sin2 = (float(jj) + rt::sample1D(seed ^ kGatherSalt, id, j, kDirectionDepth, kThetaDim)) / float(strata.m);
  phi = 2.0f * kPi * (float(k) + rt::sample1D(seed ^ kGatherSalt, id, j, kDirectionDepth, kPhiDim)) / float(strata.n);
}

}  // namespace

glm::vec3 mapRadiance(const rt::ShadingMaterial& m, const rt::ShadingFrame& sf, const KdTree& map,
                      const PrecomputedIrradiance* precomputed, const rt::SurfaceInteraction& si,
                      const DensityOptions& density, NearestPhotons& scratch, MapRead read, float roulette) {
  if (!m.hasNonDeltaPart() || map.empty()) return glm::vec3(0.0f);
  // Photons were stored with the geometric normal's side; the estimate's disc lies on it.
  const glm::vec3& ng = sf.ng;
  const glm::vec3& wo = sf.woLocal;
  const auto full = [&](const Photon& p) { return rt::evalOpaque(m, wo, sf.frame.toLocal(p.incoming())); };
  if (read == MapRead::All) return estimateRadiance(map, si.position, ng, density, scratch, full);
  if (read == MapRead::GlossyCaustic)
    return estimateRadiance(map, si.position, ng, density, scratch, full, {PhotonPath::kGlossy, PhotonPath::kDiffuse});

  if (m.hasSheen() || m.hasClearcoat()) {
    // Photon by photon: the layered base for every one, the lobes above it for diffuse paths.
    return estimateRadiance(map, si.position, ng, density, scratch, [&](const Photon& p) {
      const glm::vec3 wi = sf.frame.toLocal(p.incoming());
      const glm::vec3 f = rt::evalOpaque(m, wo, wi);
      return (p.path() & PhotonPath::kDiffuse) ? f : f - rt::evalNonLambertian(m, wo, wi);
    });
  }
  glm::vec3 radiance(0.0f);
  // The diffuse base under its Fresnel layer, for irradiance known without directions.
  const glm::vec3 diffuse = m.diffuseColor() * rt::diffuseLayerScale(m, wo);
  if (rt::maxComponent(diffuse) > 0.0f) {
    const glm::vec3 irradiance = precomputed && !precomputed->empty()
                                     ? precomputed->irradiance(si.position, ng, density.maxRadius, scratch)
                                     : estimateIrradiance(map, si.position, ng, density, scratch).irradiance;
    radiance += lambertianRadiance(diffuse, irradiance);
  }
  if (m.hasSpecular() && !m.deltaSpecular()) {
    const float p = std::clamp(rt::specularProbability(m, wo.z), 0.1f, 1.0f);
    if (roulette < p) {
      const auto glossy = [&](const Photon& photon) { return rt::evalGlossy(m, wo, sf.frame.toLocal(photon.incoming())); };
      radiance += estimateRadiance(map, si.position, ng, density, scratch, glossy, {PhotonPath::kDiffuse, 0}) / p;
    }
  }
  return radiance;
}

GatherStrata gatherStrata(int rays) {
  GatherStrata s;
  s.m = std::max(1, int(std::lround(std::sqrt(double(std::max(1, rays)) / double(kPi)))));
  s.n = std::max(1, int(std::lround(double(std::max(1, rays)) / double(s.m))));
  return s;
}

bool gatherRay(const rt::SurfaceInteraction& si, const rt::ShadingFrame& sf, GatherStrata strata, std::uint32_t id,
               std::uint32_t j, const GatherOptions& options, rt::Ray& ray) {
  float sin2, phi;
  cellAngles(strata, id, j, options.seed, sin2, phi);
  const float sinTheta = std::sqrt(std::min(sin2, rt::kOneMinusEpsilon));
  const float cosTheta = std::sqrt(std::max(0.0f, 1.0f - sin2));
  const glm::vec3 wi = sf.frame.toWorld(glm::vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta));
  if (glm::dot(wi, sf.ng) <= 0.0f) return false;
  ray = rt::spawnRay(si, wi);
  return true;
}

GatherInteraction gatherInteraction(const scene::Scene& scene, const KdTree& global, const rt::SurfaceInteraction& si,
                                    const rt::Ray& ray, glm::vec3 throughput, std::uint32_t id, std::uint32_t j, int bounce,
                                    const GatherOptions& options, NearestPhotons& scratch) {
  GatherInteraction out;
  rt::ShadingMaterial m = rt::evalMaterial(scene, si, options.textures);
  throughput *= rt::volumeTransmittance(m, si, ray);
  const rt::ShadingFrame sf(si, m);
  const float glossyU = rt::sample1D(options.seed ^ kGatherSalt, id, j, std::uint32_t(bounce), kGlossyDim);
  out.radiance = throughput * mapRadiance(m, sf, global, options.precomputed, si, options.global, scratch,
                                          MapRead::Secondary, glossyU);
  if (bounce >= options.specularBounces) return out;
  const auto dim = [&](std::uint32_t d) { return rt::sample1D(options.seed ^ kGatherSalt, id, j, std::uint32_t(bounce), d); };
  glm::vec3 wi, factor;
  if (!specularBounce(m, si, sf, dim(kBranchDim), dim(kMicrofacetUDim), dim(kMicrofacetVDim), wi, factor)) return out;
  out.throughput = throughput * factor;
  if (!(rt::maxComponent(out.throughput) > 0.0f)) return out;
  out.continues = true;
  out.next = rt::spawnRay(si, wi);
  return out;
}

bool specularBounce(const rt::ShadingMaterial& m, const rt::SurfaceInteraction& si, const rt::ShadingFrame& sf, float u,
                    float mu, float mv, glm::vec3& wi, glm::vec3& factor) {
  const float dielectric = m.dielectricWeight();
  if (u < dielectric) {
    const rt::DielectricSample d = rt::sampleDielectric(m, si, sf, u / dielectric, mu, mv);
    wi = d.wi;
    factor = d.weight;
    return d.valid;
  }
  if (!m.hasSpecular() || !m.deltaSpecular()) return false;
  wi = sf.frame.toWorld(glm::vec3(-sf.woLocal.x, -sf.woLocal.y, sf.woLocal.z));
  factor = m.specularFresnel(sf.woLocal.z) / m.opaqueProbability();
  return glm::dot(wi, sf.ng) > 0.0f;
}

IrradianceRecord combineGather(const rt::SurfaceInteraction& si, const rt::ShadingFrame& sf, GatherStrata strata,
                               std::uint32_t id, const GatherOptions& options, std::span<const GatherCell> cells) {
  const int m = strata.m, n = strata.n;
  IrradianceRecord record;
  record.position = si.position;
  record.normal = sf.ns;
  glm::vec3 rotation[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};  // local frame
  float inverseDistances = 0.0f;
  for (int j = 0; j < m * n; ++j) {
    const GatherCell& cell = cells[std::size_t(j)];
    record.irradiance += cell.radiance;
    if (std::isfinite(cell.distance) && cell.distance > 0.0f) inverseDistances += 1.0f / cell.distance;
    // Rotation gradient: turning n by delta about an axis A changes cos(theta) of direction w
    // by delta A . (n x w), so grad_r = int L (n x w) dw = int L sin(theta) v(phi) dw, with
    // v the base-plane direction a quarter turn from phi; over cosine-distributed cells of
    // solid angle pi / (MN cos(theta)) each: pi/(MN) sum tan(theta) L v.
    float sin2, phi;
    cellAngles(strata, id, std::uint32_t(j), options.seed, sin2, phi);
    const float sinTheta = std::sqrt(std::min(sin2, rt::kOneMinusEpsilon));
    const float cosTheta = std::sqrt(std::max(0.0f, 1.0f - sin2));
    const float tanTheta = sinTheta / std::max(cosTheta, 1.0e-4f);
    const glm::vec3 v(-std::sin(phi), std::cos(phi), 0.0f);
    for (int c = 0; c < 3; ++c) rotation[c] += (tanTheta * cell.radiance[c]) * v;
  }
  const float cellWeight = kPi / float(m * n);
  record.irradiance *= cellWeight;
  record.radius = inverseDistances > 0.0f ? float(m * n) / inverseDistances : std::numeric_limits<float>::infinity();

  // Translation gradient: the change of each cell's solid angle as the centre moves, from the
  // differences across the walls between neighbouring cells, each over the nearer wall distance.
  glm::vec3 translation[3] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
  auto cell = [&](int j, int k) -> const GatherCell& { return cells[std::size_t(j * n + ((k % n) + n) % n)]; };
  auto inverseMin = [](float a, float b) {
    const float d = std::min(a, b);
    return std::isfinite(d) && d > 0.0f ? 1.0f / d : 0.0f;
  };
  for (int k = 0; k < n; ++k) {
    const float phiK = 2.0f * kPi * (float(k) + 0.5f) / float(n);
    const float phiMinus = 2.0f * kPi * float(k) / float(n);
    const glm::vec3 uK(std::cos(phiK), std::sin(phiK), 0.0f);
    const glm::vec3 vMinus(-std::sin(phiMinus), std::cos(phiMinus), 0.0f);
    for (int j = 0; j < m; ++j) {
      const float sinMinus = std::sqrt(float(j) / float(m));
      const float sinPlus = std::sqrt(float(j + 1) / float(m));
      // Across the theta wall between cells (j-1, k) and (j, k).
      if (j > 0) {
        const float cos2Minus = 1.0f - float(j) / float(m);
        const float w = (2.0f * kPi / float(n)) * sinMinus * cos2Minus * inverseMin(cell(j, k).distance, cell(j - 1, k).distance);
        for (int c = 0; c < 3; ++c) translation[c] += (w * (cell(j, k).radiance[c] - cell(j - 1, k).radiance[c])) * uK;
      }
      // Across the phi wall between cells (j, k-1) and (j, k).
      const float w = (sinPlus - sinMinus) * inverseMin(cell(j, k).distance, cell(j, k - 1).distance);
      for (int c = 0; c < 3; ++c) translation[c] += (w * (cell(j, k).radiance[c] - cell(j, k - 1).radiance[c])) * vMinus;
    }
  }
  for (int c = 0; c < 3; ++c) {
    record.rotationGradient[c] = sf.frame.toWorld(rotation[c] * cellWeight);
    record.translationGradient[c] = sf.frame.toWorld(translation[c]);
  }
  return record;
}

IrradianceRecord gatherIrradiance(const scene::Scene& scene, const rt::Bvh& bvh, const KdTree& global,
                                  const rt::SurfaceInteraction& si, std::uint32_t id, const GatherOptions& options,
                                  NearestPhotons& scratch, std::uint64_t& rays) {
  const rt::ShadingFrame sf(si);
  const GatherStrata strata = gatherStrata(options.rays);
  std::vector<GatherCell> cells(std::size_t(strata.cells()));
  for (int j = 0; j < strata.cells(); ++j) {
    rt::Ray ray;
    if (!gatherRay(si, sf, strata, id, std::uint32_t(j), options, ray)) continue;
    GatherCell& cell = cells[std::size_t(j)];
    glm::vec3 throughput(1.0f);
    for (int bounce = 0;; ++bounce) {
      rt::Hit hit;
      ++rays;
      if (!bvh.intersect(ray, hit)) break;
      const rt::SurfaceInteraction h = rt::makeInteraction(scene, ray, hit);
      if (bounce == 0) cell.distance = hit.t * glm::length(ray.direction);
      const GatherInteraction step = gatherInteraction(scene, global, h, ray, throughput, id, std::uint32_t(j), bounce, options, scratch);
      cell.radiance += step.radiance;
      if (!step.continues) break;
      ray = step.next;
      throughput = step.throughput;
    }
  }
  return combineGather(si, sf, strata, id, options, cells);
}

}  // namespace pr::pm
