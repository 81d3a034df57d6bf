// Photon tracing, pass 1 (see photon_tracer.h). The controlling thread builds the emitter
// table and the projection map, then each batch of photons is one task of stage "photon trace"
// on whichever PE the schedule picks; a task reads only the Scene and Bvh and writes only its
// own batch's lists, which the controlling thread concatenates in batch order afterwards.
#include "photonmap/photon_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "common/parallel/runtime.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/interaction.h"
#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/integrator.h"
#include "raytrace/integrators/sampling.h"

namespace pr::pm {

namespace {

using rt::kPi;

// Stream selectors of sample1D(seed, photon, map, depth, dim): depth 0 is emission, depth
// k + 1 the k-th surface interaction (rt::Dim numbers are reused there).
constexpr std::uint32_t kGlobalStream = 0, kCausticStream = 1;
namespace EmitDim {
constexpr std::uint32_t kPick = 0, kPosU = 1, kPosV = 2, kDirU = 3, kDirV = 4, kTarget = 5, kEnvU = 6, kEnvV = 7;
}

// int over the sphere of spotFactor: the factor t^2 with t = (c - cosOuter) s, s the scale
// above, clamped to 1 at c >= cosOuter + 1/s, so 2 pi [ (1 - c1) + (c1 - cosOuter) / 3 ].
double spotSolidAngle(const scene::PunctualLight& light) {
  const double cosOuter = std::cos(double(light.outerConeAngle));
  const double s = 1.0 / std::max(1.0e-3, std::cos(double(light.innerConeAngle)) - cosOuter);
  const double c1 = std::min(1.0, cosOuter + 1.0 / s);
  return 2.0 * double(kPi) * ((1.0 - c1) + (c1 - cosOuter) / 3.0);
}

// A unit direction uniformly inside the cone of half-angle acos(cosMax) around axis.
glm::vec3 uniformCone(const glm::vec3& axis, float cosMax, float u, float v) {
  const float c = 1.0f - u * (1.0f - cosMax);
  const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
  const float phi = 2.0f * kPi * v;
  return rt::Frame(axis).toWorld({s * std::cos(phi), s * std::sin(phi), c});
}
glm::vec2 concentricDisc(float u, float v) {
  const float a = 2.0f * u - 1.0f, b = 2.0f * v - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = (kPi / 4.0f) * (b / a);
  } else {
    r = b;
    phi = kPi / 2.0f - (kPi / 4.0f) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

// ---- projection map: bounding spheres of the specular objects --------------------------------
// Jensen's projection map marks the directions from a light in which specular objects lie.
// parrender keeps it exact and cell-free: the bounding sphere of every specular object (per
// object and material) is the target, and a caustic photon's direction is drawn uniformly from
// the cone a target subtends (for a directional light: from the target's disc on the emission
// plane), the target picked in proportion to its solid angle (area). A direction inside m
// overlapping cones has pdf sum_i [inside i] / Omega_total, so its photon carries
// Phi(direction) Omega_total / (N m) - unbiased for the light that reaches the union of the
// spheres, with no photon wasted on a cell that is only partly covered.
struct Target {
  glm::vec3 centre;
  float radius;
};

// A material that can bend light into a caustic: one that may be smooth, so that its
// refracting part or its opaque lobe is ideal specular (conservative for textured roughness, as
// scene::EffectAnalysis). Frosted glass scatters light as a glossy surface does: no caustic.
bool canFocus(const scene::Material& m) {
  const bool textured = m.metallicRoughnessTexture.present();
  const float roughnessMin = textured ? 0.0f : std::clamp(m.roughnessFactor, 0.0f, 1.0f);
  return roughnessMin < scene::kIdealSpecularRoughness;
}

std::vector<Target> specularTargets(const scene::Scene& scene) {
  std::vector<Target> targets;
  auto addRange = [&](std::uint32_t first, std::uint32_t count) {
    std::vector<scene::Bounds> byMaterial(scene.materials.size());
    for (std::uint32_t t = first; t < first + count && t < scene.triangles.size(); ++t) {
      const scene::Triangle& tri = scene.triangles[t];
      if (!canFocus(scene.materials[tri.material])) continue;
      for (std::uint32_t v : tri.v) byMaterial[tri.material].extend(scene.positions[v]);
    }
    for (const scene::Bounds& b : byMaterial)
      if (!b.empty()) {
        // 0.1 % larger than the box's half diagonal: rounding cannot cut off a silhouette.
        const float r = 0.5f * glm::length(b.extent());
        targets.push_back({b.center(), r * 1.001f + 1.0e-6f});
      }
  };
  if (scene.objects.empty()) addRange(0, std::uint32_t(scene.triangles.size()));
  for (const scene::Object& o : scene.objects) addRange(o.firstTriangle, o.triangleCount);
  return targets;
}

// ---- emitters -------------------------------------------------------------------------------
// One entry per punctual light, and one for all emissive triangles together (sampled by power,
// as LightSampler does). power: luminance of the emitted flux, used to split the photons.
// Emitter::light of the environment (Scene::environment).
constexpr int kEnvironmentEmitter = -2;

struct Emitter {
  int light = -1;  // index into Scene::lights, -1 = the area lights, kEnvironmentEmitter
  double power = 0.0;
};

struct Setup {
  const scene::Scene* scene;
  PhotonOptions options_;
  const PhotonOptions* options;
  std::vector<Emitter> emitters;
  std::vector<std::size_t> firstPhoton[2];  // per map: emitter e owns photons [first[e], first[e+1])
  std::vector<std::uint32_t> areaTriangles;
  std::vector<float> areaCdf;     // by luminance(emission factor) * area * sides
  std::vector<float> areaProb;    // pick probability of each area triangle
  std::vector<Target> targets;
  glm::vec3 sceneCentre{0.0f};
  float sceneRadius = 0.0f;
  bool simulate[2] = {true, true};
};

bool twoSided(const scene::Material& m) { return m.doubleSided; }

// The photons of one map are split over the emitters in proportion to their power, by largest
// remainder (the counts sum to n exactly and depend only on the scene).
std::vector<std::size_t> splitPhotons(const std::vector<double>& power, std::size_t n) {
  std::vector<std::size_t> first(power.size() + 1, 0);
  const double total = std::accumulate(power.begin(), power.end(), 0.0);
  if (!(total > 0.0) || n == 0) return first;
  std::vector<std::size_t> count(power.size());
  std::vector<std::pair<double, std::size_t>> rest;
  std::size_t given = 0;
  for (std::size_t e = 0; e < power.size(); ++e) {
    const double exact = double(n) * power[e] / total;
    count[e] = std::size_t(std::floor(exact));
    given += count[e];
    rest.push_back({-(exact - std::floor(exact)), e});
  }
  std::sort(rest.begin(), rest.end());
  for (std::size_t i = 0; given < n && i < rest.size(); ++i, ++given) ++count[rest[i].second];
  for (std::size_t e = 0; e < power.size(); ++e) first[e + 1] = first[e] + count[e];
  return first;
}

// Solid angle a sphere subtends from p (4 pi when p is inside it), and the cone's cosine.
float coneOf(const Target& t, const glm::vec3& p, float& cosMax, glm::vec3& axis) {
  const glm::vec3 d = t.centre - p;
  const float dist2 = glm::dot(d, d);
  if (dist2 <= t.radius * t.radius) {
    cosMax = -1.0f;
    axis = glm::vec3(0, 0, 1);
    return 4.0f * kPi;
  }
  const float dist = std::sqrt(dist2);
  axis = d / dist;
  cosMax = std::sqrt(std::max(0.0f, 1.0f - t.radius * t.radius / dist2));
  return 2.0f * kPi * (1.0f - cosMax);
}

// A caustic direction from p towards the targets (see the projection map above): returns the
// weight Omega_total / m, 0 when there is no target.
float sampleTowardsTargets(const Setup& s, const glm::vec3& p, float pick, float u, float v, glm::vec3& dir) {
  float total = 0.0f;
  std::vector<float> omega(s.targets.size());
  std::vector<float> cosMax(s.targets.size());
  std::vector<glm::vec3> axis(s.targets.size());
  for (std::size_t i = 0; i < s.targets.size(); ++i) total += omega[i] = coneOf(s.targets[i], p, cosMax[i], axis[i]);
  if (!(total > 0.0f)) return 0.0f;
  std::size_t chosen = s.targets.size() - 1;
  float running = 0.0f;
  for (std::size_t i = 0; i < s.targets.size(); ++i) {
    running += omega[i];
    if (pick * total < running) {
      chosen = i;
      break;
    }
  }
  dir = uniformCone(axis[chosen], cosMax[chosen], u, v);
  int inside = 0;
  for (std::size_t i = 0; i < s.targets.size(); ++i)
    if (cosMax[i] <= -1.0f || glm::dot(dir, axis[i]) >= cosMax[i] * (1.0f - 1.0e-6f)) ++inside;
  return total / float(std::max(inside, 1));
}

}  // namespace

glm::vec2 stratifiedEmission(std::size_t j, std::size_t n, float u, float v) {
  const std::size_t m = std::max<std::size_t>(1, std::size_t(std::sqrt(double(n))));
  // The n - m^2 photons past the grid are drawn independently: giving them cells again would
  // put twice the flux into the first cells.
  if (j >= m * m) return {u, v};
  return {std::min((float(j % m) + u) / float(m), rt::kOneMinusEpsilon),
          std::min((float(j / m) + v) / float(m), rt::kOneMinusEpsilon)};
}

namespace {

// The origin of a photon travelling along dir from far away (a directional light, the
// environment): a point on the disc of the scene's bounding sphere perpendicular to dir,
// upstream of the scene - or, for a caustic photon, on the discs the specular targets project
// onto that plane, one picked by area - and the area the photon stands for (the disc's, or the
// targets' total over how many of them cover the point). False without a target to aim at.
bool parallelOrigin(const Setup& s, const glm::vec3& dir, bool caustic, glm::vec2 dirUv, float pick, glm::vec3& origin,
                    float& area) {
  const rt::Frame f(dir);
  const glm::vec3 plane = s.sceneCentre - dir * (s.sceneRadius * 1.01f);
  if (!caustic) {
    const glm::vec2 d = concentricDisc(dirUv.x, dirUv.y) * s.sceneRadius;
    origin = plane + f.toWorld({d.x, d.y, 0.0f});
    area = kPi * s.sceneRadius * s.sceneRadius;
    return true;
  }
  float total = 0.0f;
  for (const Target& t : s.targets) total += kPi * t.radius * t.radius;
  if (!(total > 0.0f)) return false;
  std::size_t chosen = s.targets.size() - 1;
  float running = 0.0f;
  for (std::size_t i = 0; i < s.targets.size(); ++i) {
    running += kPi * s.targets[i].radius * s.targets[i].radius;
    if (pick * total < running) {
      chosen = i;
      break;
    }
  }
  const Target& t = s.targets[chosen];
  const glm::vec2 d = concentricDisc(dirUv.x, dirUv.y) * t.radius;
  const glm::vec3 c = f.toLocal(t.centre - plane);
  origin = plane + f.toWorld({c.x + d.x, c.y + d.y, 0.0f});
  int inside = 0;
  for (const Target& o : s.targets) {
    const glm::vec3 q = f.toLocal(o.centre - origin);
    if (q.x * q.x + q.y * q.y <= o.radius * o.radius * 1.000001f) ++inside;
  }
  area = total / float(std::max(inside, 1));
  return true;
}

// Photon `index` (global within its map) of emitter e, which owns n photons from `first` on.
bool emit(const Setup& s, int map, std::size_t e, std::size_t index, EmittedPhoton& out) {
  const std::uint64_t seed = s.options->seed;
  const auto sample = [&](std::uint32_t dim) { return rt::sample1D(seed, std::uint32_t(index), map, 0, dim); };
  const std::size_t first = s.firstPhoton[map][e], n = s.firstPhoton[map][e + 1] - first;
  const std::size_t j = index - first;
  const glm::vec2 dirUv = stratifiedEmission(j, n, sample(EmitDim::kDirU), sample(EmitDim::kDirV));
  const bool caustic = map == kCausticStream;
  const Emitter& em = s.emitters[e];
  const scene::Scene& scene = *s.scene;
  if (em.light == kEnvironmentEmitter) {
    // From the environment: a direction by its own distribution (where the light comes
    // from), then as a directional light along the opposite: power L(w) area / (pdf(w) N).
    float pdf = 0.0f;
    const glm::vec3 towards = scene.environment->sample(sample(EmitDim::kEnvU), sample(EmitDim::kEnvV), pdf);
    if (!(pdf > 0.0f) || !std::isfinite(pdf)) return false;
    glm::vec3 origin;
    float area;
    if (!parallelOrigin(s, -towards, caustic, dirUv, sample(EmitDim::kTarget), origin, area)) return false;
    out.ray = rt::Ray{origin, 0.0f, -towards, rt::kInfinity};
    out.power = scene.environment->radiance(towards) * (area / (pdf * float(n)));
    out.range = 0.0f;
    return rt::maxComponent(out.power) > 0.0f && rt::isFinite(out.power);
  }
  if (em.light >= 0) {
    const scene::PunctualLight& light = scene.lights[std::size_t(em.light)];
    const glm::vec3 colour = light.color * light.intensity;
    out.range = light.range;
    if (light.type == scene::LightType::Directional) {
      // A disc of the scene's bounding sphere, perpendicular to the light, upstream of it:
      // flux E pi R^2 (E in lux at normal incidence).
      glm::vec3 origin;
      float area;
      if (!parallelOrigin(s, light.direction, caustic, dirUv, sample(EmitDim::kTarget), origin, area)) return false;
      out.ray = rt::Ray{origin, 0.0f, light.direction, rt::kInfinity};
      out.power = colour * area / float(n);
      out.range = 0.0f;
      return true;
    }
    glm::vec3 dir;
    float solidAngle;
    if (caustic) {
      solidAngle = sampleTowardsTargets(s, light.position, sample(EmitDim::kTarget), dirUv.x, dirUv.y, dir);
      if (!(solidAngle > 0.0f)) return false;
    } else if (light.type == scene::LightType::Spot) {
      const float cosOuter = std::cos(light.outerConeAngle);
      dir = uniformCone(light.direction, cosOuter, dirUv.x, dirUv.y);
      solidAngle = 2.0f * kPi * (1.0f - cosOuter);
    } else {
      dir = uniformCone(glm::vec3(0, 0, 1), -1.0f, dirUv.x, dirUv.y);
      solidAngle = 4.0f * kPi;
    }
    float factor = 1.0f;
    if (light.type == scene::LightType::Spot) factor = scene::spotFactor(light, dir);
    out.ray = rt::Ray{light.position, 0.0f, dir, rt::kInfinity};
    out.power = colour * (factor * solidAngle / float(n));  // I(w) / (N pdf(w)), pdf = 1 / solidAngle
    return factor > 0.0f;
  }
  // Area lights: a triangle by power, a point uniformly on it, a cosine-weighted direction on
  // its emitting side (flux L cos / (pdf_A pdf_w) = L pi / pdf_A for the cosine lobe). Only the
  // direction is stratified: stratifying the pick by j as well would tie each triangle to a
  // band of direction cells.
  const float pick = sample(EmitDim::kPick);
  const std::size_t k = std::min(std::size_t(std::upper_bound(s.areaCdf.begin(), s.areaCdf.end(), pick) - s.areaCdf.begin()),
                                 s.areaCdf.size() - 1);
  const std::uint32_t tri = s.areaTriangles[k];
  const scene::Triangle& t = scene.triangles[tri];
  const glm::vec2 b = rt::uniformTriangle(sample(EmitDim::kPosU), sample(EmitDim::kPosV));
  const glm::vec3 p0 = scene.positions[t.v[0]], p1 = scene.positions[t.v[1]], p2 = scene.positions[t.v[2]];
  const glm::vec3 q = (1.0f - b.x - b.y) * p0 + b.x * p1 + b.y * p2;
  const glm::vec3 cr = glm::cross(p1 - p0, p2 - p0);
  const float area = 0.5f * glm::length(cr);
  if (!(area > 0.0f)) return false;
  const glm::vec3 ng = cr / (2.0f * area);
  const scene::Material& mat = scene.materials[t.material];
  // Which side: the front, or either with equal probability when double-sided.
  const bool sides = twoSided(mat);
  float u = dirUv.x;
  glm::vec3 side = ng;
  if (sides) {
    if (u < 0.5f) {
      u *= 2.0f;
    } else {
      u = std::min(2.0f * u - 1.0f, rt::kOneMinusEpsilon);
      side = -ng;
    }
  }
  // The emitter's material at q, textures applied, seen from the emitting side.
  const rt::SurfaceInteraction si =
      rt::makeInteraction(scene, rt::Ray{q + side, 0.0f, -side, rt::kInfinity}, rt::Hit{1.0f, tri, b.x, b.y});
  const glm::vec3 le = rt::evalMaterial(scene, si, s.options->textures).emission;
  const float pdfArea = s.areaProb[k] / area;
  glm::vec3 dir;
  float weight;  // cos / pdf_w over the side's hemisphere
  if (caustic) {
    weight = sampleTowardsTargets(s, q, sample(EmitDim::kTarget), u, dirUv.y, dir);
    weight *= std::max(0.0f, glm::dot(dir, side));
  } else {
    dir = rt::Frame(side).toWorld(rt::cosineHemisphere(u, dirUv.y));
    weight = kPi;
  }
  if (!(weight > 0.0f)) return false;
  out.ray = rt::Ray{rt::spawnOrigin(si, dir), 0.0f, dir, rt::kInfinity};
  out.power = le * (weight * (sides ? 2.0f : 1.0f) / (pdfArea * float(n)));
  out.range = 0.0f;
  return rt::maxComponent(out.power) > 0.0f && rt::isFinite(out.power);
}

// One surface interaction of photon `index` of `map` (see photonInteraction in the header).
PhotonInteraction interact(const Setup& s, int map, std::uint32_t index, int bounce, glm::vec3 power, float range,
                           std::uint8_t path, const rt::Ray& ray, const rt::Hit& hit, const rt::SurfaceInteraction& si) {
  PhotonInteraction out;
  const bool caustic = map == kCausticStream;
  const std::uint64_t seed = s.options->seed;
  if (bounce == 0) power *= scene::rangeWindow(hit.t * glm::length(ray.direction), range);
  rt::ShadingMaterial m = rt::evalMaterial(*s.scene, si, s.options->textures);
  // A photon that crossed an absorbing solid arrives attenuated (KHR_materials_volume).
  power *= rt::volumeTransmittance(m, si, ray);
  const auto sample = [&](std::uint32_t dim) { return rt::sample1D(seed, index, map, std::uint32_t(bounce + 1), dim); };

  // Storage: the photon's incident flux and direction wherever the surface has a part that is
  // not a perfect mirror (diffuse, a rough specular lobe, sheen, a clear coat), whatever the
  // photon does next: the estimates weigh it by that part's BRDF for its direction. The caustic
  // map keeps only the photons that came along L S+: every earlier interaction of a caustic
  // photon was a specular choice, so any but its first hit (the specular object it was aimed
  // at, or what stood before it) is one.
  if (m.hasNonDeltaPart() && (!caustic || bounce > 0)) {
    out.stored = true;
    out.photon = Photon::make(si.position, power, si.wo, caustic ? PhotonMapKind::Caustic : PhotonMapKind::Global, bounce, path);
    out.normal = si.frontFace ? si.geometricNormal : -si.geometricNormal;
  }

  // Choose the part by Russian roulette over the whole BSDF: the dielectric with probability
  // equal to its weight, reflection against refraction by the Fresnel term (about a sampled
  // microfacet normal when rough), else one
  // component of the opaque part (probability 1 - dielectric, divided out) - the Lambertian
  // base, the glossy lobes or an ideal mirror - weighted by its own BRDF, so the reflection the
  // photon takes is of that kind and its path's PhotonPath bits say so. Each choice's
  // probability cancels its weight, so the factor left, f cos / pdf, is the part's albedo along
  // the sampled direction. A caustic photon goes on only through a specular choice (Jensen):
  // one the diffuse or glossy part takes has left L S+, and was stored above.
  const rt::ShadingFrame sf(si, m);
  const float dielectric = m.dielectricWeight();
  const float opaque = 1.0f - dielectric;
  const float lobe = sample(rt::Dim::kLobe);
  glm::vec3 wi, factor;
  bool specular;
  if (lobe < dielectric) {
    // Flux is conserved through refraction: no eta^2 (that is radiance). A rough (frosted)
    // dielectric scatters about a microfacet normal: a glossy choice.
    const rt::DielectricSample d =
        rt::sampleDielectric(m, si, sf, lobe / dielectric, sample(rt::Dim::kBsdfU), sample(rt::Dim::kBsdfV), rt::Transport::Flux);
    if (!d.valid) return out;
    wi = d.wi;
    factor = d.weight;
    specular = d.delta;
    if (!d.delta) path |= PhotonPath::kGlossy;
  } else {
    const float u = std::min(dielectric > 0.0f ? (lobe - dielectric) / opaque : lobe, rt::kOneMinusEpsilon);
    const rt::PartSample part = rt::sampleOpaquePart(m, sf.woLocal, u, sample(rt::Dim::kBsdfU), sample(rt::Dim::kBsdfV));
    const rt::BsdfSample& b = part.sample;
    if (!b.valid) return out;
    wi = sf.frame.toWorld(b.wi);
    if (glm::dot(wi, sf.ng) <= 0.0f) return out;  // a reflection leaves on the side it arrived from
    factor = b.weight / opaque;
    specular = b.delta;
    if (part.part == rt::OpaquePart::Diffuse) path |= PhotonPath::kDiffuse;
    if (part.part == rt::OpaquePart::Glossy) path |= PhotonPath::kGlossy;
  }
  if (caustic && !specular) return out;  // glossy or diffuse: no longer an L S+ D path

  // Absorption by Russian roulette (Jensen): survive with q = the largest channel of the
  // factor (capped at 1), and carry power * factor / q, so E[power'] = power * factor.
  // For a Lambertian surface of albedo rho this is Jensen's rule: survive with rho, keep Phi.
  const float q = std::min(1.0f, rt::maxComponent(factor));
  if (!(q > 0.0f) || sample(rt::Dim::kRoulette) >= q) return out;
  power *= factor / q;
  if (!(rt::maxComponent(power) > 0.0f) || !rt::isFinite(power) || bounce + 1 >= s.options->maxBounces) return out;
  out.continues = true;
  out.power = power;
  out.path = path;
  out.next = rt::spawnRay(si, wi);
  return out;
}

// Fills s (whose options_ are set) for the scene: emitters, targets, photon split.
void makeSetup(Setup& s, const scene::Scene& scene) {
  s.scene = &scene;
  s.options = &s.options_;
  const PhotonOptions& options = s.options_;
  scene::Bounds bounds = scene.bounds;
  if (bounds.empty())
    for (const glm::vec3& p : scene.positions) bounds.extend(p);
  s.sceneCentre = bounds.center();
  s.sceneRadius = std::max(0.5f * glm::length(bounds.extent()), 1.0e-6f);
  s.targets = specularTargets(scene);

  std::vector<double> causticPower;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const scene::PunctualLight& l = scene.lights[i];
    const double lum = double(rt::luminance(glm::max(l.color * l.intensity, glm::vec3(0.0f))));
    double power = 0.0;
    switch (l.type) {
      case scene::LightType::Point: power = 4.0 * double(kPi) * lum; break;
      case scene::LightType::Spot: power = spotSolidAngle(l) * lum; break;
      case scene::LightType::Directional: power = double(kPi) * s.sceneRadius * s.sceneRadius * lum; break;
    }
    if (!(power > 0.0) || !std::isfinite(power)) continue;
    s.emitters.push_back({int(i), power});
  }
  double areaPower = 0.0;
  std::vector<double> triPower;
  for (const scene::AreaLight& a : scene.areaLights) {
    if (a.triangle >= scene.triangles.size() || !(a.area > 0.0f) || !std::isfinite(a.area)) continue;
    const scene::Material& m = scene.materials[scene.triangles[a.triangle].material];
    const double p = double(rt::luminance(glm::max(m.emission(), glm::vec3(0.0f)))) * a.area * double(kPi) *
                     (m.doubleSided ? 2.0 : 1.0);
    if (!(p > 0.0) || !std::isfinite(p)) continue;
    s.areaTriangles.push_back(a.triangle);
    triPower.push_back(p);
    areaPower += p;
  }
  double running = 0.0;
  for (std::size_t i = 0; i < triPower.size(); ++i) {
    running += triPower[i];
    s.areaCdf.push_back(i + 1 == triPower.size() ? 1.0f : float(running / areaPower));
    s.areaProb.push_back(float(triPower[i] / areaPower));
  }
  if (areaPower > 0.0) s.emitters.push_back({-1, areaPower});
  // The environment's flux through the scene's disc from every direction: pi R^2 4 pi mean L.
  if (scene.environment && scene.environment->meanLuminance() > 0.0f)
    s.emitters.push_back({kEnvironmentEmitter, double(scene.environment->meanLuminance()) * 4.0 * double(kPi) *
                                                   double(kPi) * double(s.sceneRadius) * double(s.sceneRadius)});

  // The caustic photons are split by the power each emitter sends towards the targets (the
  // projection map's solid angle fraction), so each carries about the same flux.
  std::vector<double> power;
  for (const Emitter& e : s.emitters) {
    power.push_back(e.power);
    double fraction = 0.0;
    if (!s.targets.empty()) {
      if (e.light == kEnvironmentEmitter ||
          (e.light >= 0 && scene.lights[std::size_t(e.light)].type == scene::LightType::Directional)) {
        for (const Target& t : s.targets) fraction += double(t.radius * t.radius) / double(s.sceneRadius * s.sceneRadius);
      } else {
        const glm::vec3 p = e.light >= 0 ? scene.lights[std::size_t(e.light)].position : s.sceneCentre;
        for (const Target& t : s.targets) {
          float c;
          glm::vec3 axis;
          fraction += double(coneOf(t, p, c, axis)) / (4.0 * double(kPi));
        }
        if (e.light < 0) fraction = std::max(fraction, 1.0e-3);  // area lights: a rough share, never zero
      }
    }
    causticPower.push_back(e.power * std::min(fraction, 1.0));
  }
  // The global map lights indirect diffuse light and what glossy rays see.
  s.simulate[kGlobalStream] = options.effects.has(scene::Effect::IndirectDiffuse) || options.effects.has(scene::Effect::GlossySpecular);
  s.simulate[kCausticStream] = options.effects.has(scene::Effect::Caustics);
  if (s.targets.empty()) s.simulate[kCausticStream] = false;
  s.firstPhoton[kGlobalStream] = splitPhotons(power, s.simulate[kGlobalStream] ? options.globalPhotons : 0);
  s.firstPhoton[kCausticStream] = splitPhotons(causticPower, s.simulate[kCausticStream] ? options.causticPhotons : 0);
}

}  // namespace

struct PhotonSource::Impl {
  Setup setup;
};

PhotonSource::PhotonSource(const scene::Scene& scene, const PhotonOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->setup.options_ = options;
  makeSetup(impl_->setup, scene);
}

PhotonSource::~PhotonSource() = default;

std::size_t PhotonSource::emitted(PhotonMapKind map) const { return impl_->setup.firstPhoton[int(map)].back(); }

PhotonStats PhotonSource::plan() const {
  const Setup& s = impl_->setup;
  PhotonStats stats;
  stats.globalEmitted = emitted(PhotonMapKind::Global);
  stats.causticEmitted = emitted(PhotonMapKind::Caustic);
  stats.globalSkipped = s.options_.globalPhotons - stats.globalEmitted;
  stats.causticSkipped = s.options_.causticPhotons - stats.causticEmitted;
  stats.causticTargets = s.targets.size();
  return stats;
}

bool PhotonSource::emit(PhotonMapKind map, std::size_t index, EmittedPhoton& out) const {
  const Setup& s = impl_->setup;
  const std::vector<std::size_t>& first = s.firstPhoton[int(map)];
  if (index >= first.back()) return false;
  const std::size_t e = std::size_t(std::upper_bound(first.begin(), first.end(), index) - first.begin()) - 1;
  return pm::emit(s, int(map), e, index, out);
}

PhotonInteraction PhotonSource::interact(PhotonMapKind map, std::uint32_t index, int bounce, const glm::vec3& power,
                                         float range, std::uint8_t path, const rt::Ray& ray, const rt::Hit& hit,
                                         const rt::SurfaceInteraction& si) const {
  return pm::interact(impl_->setup, int(map), index, bounce, power, range, path, ray, hit, si);
}

void tracePhoton(const PhotonSource& source, const scene::Scene& scene, const rt::Bvh& bvh, PhotonMapKind map,
                 std::uint32_t index, std::vector<Photon>& store, std::vector<glm::vec3>& normals) {
  EmittedPhoton photon;
  if (!source.emit(map, index, photon)) return;
  rt::Ray ray = photon.ray;
  glm::vec3 power = photon.power;
  std::uint8_t path = 0;
  for (int bounce = 0;; ++bounce) {
    rt::Hit hit;
    if (!bvh.intersect(ray, hit)) return;
    const PhotonInteraction step = source.interact(map, index, bounce, power, photon.range, path, ray, hit,
                                                   rt::makeInteraction(scene, ray, hit));
    if (step.stored) {
      store.push_back(step.photon);
      normals.push_back(step.normal);
    }
    if (!step.continues) return;
    ray = step.next;
    power = step.power;
    path = step.path;
  }
}

void recordPhotonCounters(par::Runtime& runtime, const std::vector<std::array<std::uint64_t, 4>>& perPe,
                          const PhotonStats& stats) {
  for (int p = 0; p < runtime.pes(); ++p) {
    const std::array<std::uint64_t, 4>& row = perPe[std::size_t(p)];
    runtime.addCounter("Photons/global_emitted", p, double(row[0]));
    runtime.addCounter("Photons/caustic_emitted", p, double(row[1]));
    runtime.addCounter("Photons/global_stored", p, double(row[2]));
    runtime.addCounter("Photons/caustic_stored", p, double(row[3]));
  }
  runtime.addCounter("Photons/global_skipped", 0, double(stats.globalSkipped));
  runtime.addCounter("Photons/caustic_skipped", 0, double(stats.causticSkipped));
}

PhotonLists tracePhotonLists(const scene::Scene& scene, const rt::Bvh& bvh, const PhotonOptions& options,
                             par::Runtime& runtime) {
  const PhotonSource source(scene, options);
  PhotonLists out;
  out.stats = source.plan();
  const std::size_t emitted[2] = {out.stats.globalEmitted, out.stats.causticEmitted};

  // Batches: the global map's first, then the caustic map's; a batch never mixes maps.
  const std::size_t batch = std::max<std::size_t>(1, options.batchSize);
  const std::size_t batches[2] = {(emitted[0] + batch - 1) / batch, (emitted[1] + batch - 1) / batch};
  const std::size_t tasks = batches[0] + batches[1];
  out.stats.tasks = tasks;
  std::vector<std::vector<Photon>> lists(tasks);
  std::vector<std::vector<glm::vec3>> normals(tasks);
  // Per PE, for the run record: photons emitted and stored, by map (each PE writes its own row).
  std::vector<std::array<std::uint64_t, 4>> perPe(std::size_t(runtime.pes()), std::array<std::uint64_t, 4>{});
  if (tasks > 0) {
    runtime.runStage("photon trace", par::TaskSet::uniform(tasks), [&](par::Pe& pe, par::TaskId t) {
      const std::size_t task = std::size_t(t);
      const int map = task < batches[0] ? kGlobalStream : kCausticStream;
      const std::size_t b = map == kGlobalStream ? task : task - batches[0];
      const std::size_t begin = b * batch, end = std::min(emitted[map], begin + batch);
      for (std::size_t i = begin; i < end; ++i)
        tracePhoton(source, scene, bvh, PhotonMapKind(map), std::uint32_t(i), lists[task], normals[task]);
      std::array<std::uint64_t, 4>& row = perPe[std::size_t(pe.id())];
      row[map == kGlobalStream ? 0 : 1] += end - begin;
      row[map == kGlobalStream ? 2 : 3] += lists[task].size();
    });
  }
  // The figures leave the tracer as run-record counters (STYLE.md section 4). Photons not traced
  // at all are the controller's decision: booked on PE 0.
  recordPhotonCounters(runtime, perPe, out.stats);
  for (std::size_t t = 0; t < tasks; ++t) {
    const bool global = t < batches[0];
    std::vector<Photon>& dst = global ? out.global : out.caustic;
    std::vector<glm::vec3>& dstNormals = global ? out.globalNormals : out.causticNormals;
    dst.insert(dst.end(), lists[t].begin(), lists[t].end());
    dstNormals.insert(dstNormals.end(), normals[t].begin(), normals[t].end());
  }
  out.stats.globalStored = out.global.size();
  out.stats.causticStored = out.caustic.size();
  return out;
}

PhotonMaps tracePhotons(const scene::Scene& scene, const rt::Bvh& bvh, const PhotonOptions& options,
                        par::Runtime& runtime) {
  PhotonLists lists = tracePhotonLists(scene, bvh, options, runtime);
  PhotonMaps maps;
  maps.stats = lists.stats;
  maps.global = KdTree::build(std::move(lists.global), runtime);
  maps.caustic = KdTree::build(std::move(lists.caustic), runtime);
  return maps;
}

}  // namespace pr::pm
