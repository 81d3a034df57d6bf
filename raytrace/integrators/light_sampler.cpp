// Light sampling (see light_sampler.h). Built on the controlling thread before the render;
// sample* run on any PE shading a hit and read only the Scene.
#include "raytrace/integrators/light_sampler.h"

#include <algorithm>
#include <cmath>

#include "raytrace/integrators/bsdf.h"
#include "raytrace/integrators/sampling.h"

namespace pr::rt {

namespace {
constexpr uint32_t kNotALight = ~0u;

}  // namespace

LightSampler::LightSampler(const scene::Scene& scene, bool textures)
    : scene_(&scene), textures_(textures), lightOf_(scene.triangles.size(), kNotALight) {
  double total = 0.0;
  std::vector<double> power;
  std::vector<float> area;
  for (const scene::AreaLight& a : scene.areaLights) {
    if (a.triangle >= scene.triangles.size() || !(a.area > 0.0f) || !std::isfinite(a.area)) continue;
    if (lightOf_[a.triangle] != kNotALight) continue;
    const scene::Material& m = scene.materials[scene.triangles[a.triangle].material];
    const double p = double(luminance(glm::max(m.emission(), glm::vec3(0.0f)))) * a.area;
    if (!(p > 0.0) || !std::isfinite(p)) continue;
    lightOf_[a.triangle] = uint32_t(triangles_.size());
    triangles_.push_back(a.triangle);
    power.push_back(p);
    area.push_back(a.area);
    total += p;
  }
  double running = 0.0;
  for (size_t i = 0; i < power.size(); ++i) {
    running += power[i];
    // The last entry is exactly 1 so every pick in [0, 1) finds a light.
    cdf_.push_back(i + 1 == power.size() ? 1.0f : float(running / total));
    probability_.push_back(float(power[i] / total) / area[i]);
  }
}

bool LightSampler::samplePunctual(const scene::PunctualLight& light, const SurfaceInteraction& si, LightSample& out) const {
  const glm::vec3 colour = light.color * light.intensity;
  if (light.type == scene::LightType::Directional) {
    out.wi = -light.direction;
    out.radiance = colour;
    out.pdf = 0.0f;
    out.shadowRay = spawnRay(si, out.wi);
    return maxComponent(colour) > 0.0f;
  }
  const glm::vec3 toLight = light.position - si.position;
  const float d2 = glm::dot(toLight, toLight);
  if (!(d2 > 0.0f) || !std::isfinite(d2)) return false;  // the point sits on the light
  const float d = std::sqrt(d2);
  out.wi = toLight / d;
  float factor = scene::rangeWindow(d, light.range) / d2;  // inverse-square law, I / d^2
  if (light.type == scene::LightType::Spot) factor *= scene::spotFactor(light, -out.wi);
  if (!(factor > 0.0f) || !std::isfinite(factor)) return false;
  out.radiance = colour * factor;
  out.pdf = 0.0f;
  out.shadowRay = spawnRayTo(si, light.position);
  return true;
}

bool LightSampler::sampleArea(const SurfaceInteraction& si, float pick, float u, float v, LightSample& out) const {
  if (cdf_.empty()) return false;
  const size_t i = std::min(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), pick) - cdf_.begin()), cdf_.size() - 1);
  const uint32_t tri = triangles_[i];
  const glm::vec2 b = uniformTriangle(u, v);
  const scene::Triangle& t = scene_->triangles[tri];
  const glm::vec3 q = (1.0f - b.x - b.y) * scene_->positions[t.v[0]] + b.x * scene_->positions[t.v[1]] +
                      b.y * scene_->positions[t.v[2]];
  // The light point as a surface interaction seen along the ray from si: its frontFace says
  // whether the emitter faces si, and its offset origin keeps the shadow ray off both ends.
  const SurfaceInteraction ls = makeInteraction(*scene_, Ray{si.position, 0.0f, q - si.position, kInfinity},
                                                Hit{1.0f, tri, b.x, b.y});
  const glm::vec3 toLight = ls.position - si.position;
  const float d2 = glm::dot(toLight, toLight);
  if (!(d2 > 0.0f) || !std::isfinite(d2)) return false;
  const float d = std::sqrt(d2);
  out.wi = toLight / d;
  const float cosLight = std::fabs(glm::dot(ls.geometricNormal, out.wi));
  const ShadingMaterial m = evalMaterial(*scene_, ls, textures_);
  const glm::vec3 le = emittedRadiance(m, ls);
  if (maxComponent(le) <= 0.0f) return false;
  out.pdf = areaPdf(tri, d, cosLight);
  if (!(out.pdf > 0.0f) || !std::isfinite(out.pdf)) return false;
  out.radiance = le / out.pdf;
  out.shadowRay = spawnRayTo(si, ls);
  return isFinite(out.radiance);
}

float LightSampler::areaPdf(uint32_t triangle, float distance, float cosLight) const {
  if (triangle >= lightOf_.size() || lightOf_[triangle] == kNotALight) return 0.0f;
  // Grazing emitters: the solid-angle pdf diverges; such samples carry no light anyway.
  if (!(cosLight > 1.0e-6f)) return 0.0f;
  return probability_[lightOf_[triangle]] * distance * distance / cosLight;
}

}  // namespace pr::rt
