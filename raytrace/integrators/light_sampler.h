// Light sampling for next-event estimation: the scene's punctual lights (point, spot,
// directional, glTF KHR_lights_punctual falloff) and its emissive triangles as area lights,
// one picked by emitted power (luminance x area) and a point on it uniformly by area. Built
// once per render from the Scene; read-only and shared by every PE.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/scene.h"
#include "raytrace/core/interaction.h"

namespace pr::rt {

// Incident light at a shading point from one light sample.
struct LightSample {
  glm::vec3 wi{0.0f};        // unit, towards the light
  glm::vec3 radiance{0.0f};  // incident radiance / pdf (area), or irradiance at normal incidence (punctual)
  float pdf = 0.0f;          // solid-angle pdf of the sample; 0 for a delta (punctual) light
  Ray shadowRay;             // the segment that must be unoccluded
};

class LightSampler {
 public:
  // textures = false: emitters are evaluated without their emissive texture (plan: textures off).
  explicit LightSampler(const scene::Scene& scene, bool textures = true);

  bool hasAreaLights() const { return !cdf_.empty(); }
  // The emissive triangles sampled as area lights (scene triangle indices).
  const std::vector<uint32_t>& emitters() const { return triangles_; }
  // Bytes of the sampler's own tables (pick distribution, per-triangle light index).
  size_t tableBytes() const {
    return cdf_.size() * sizeof(float) + probability_.size() * sizeof(float) + triangles_.size() * sizeof(uint32_t) +
           lightOf_.size() * sizeof(uint32_t);
  }

  // A punctual light's contribution at si; false when it cannot reach si (outside its range
  // or spot cone, or si sits on the light).
  bool samplePunctual(const scene::PunctualLight& light, const SurfaceInteraction& si, LightSample& out) const;

  // One area-light sample at si with (pick, u, v) in [0,1)^3; false when the sampled point
  // does not light si (back of a one-sided emitter, grazing, zero distance).
  bool sampleArea(const SurfaceInteraction& si, float pick, float u, float v, LightSample& out) const;

  // Solid-angle pdf with which sampleArea would have produced the point `light` as seen from
  // `distance` away along a direction making cosine cosLight with the light's normal.
  float areaPdf(uint32_t triangle, float distance, float cosLight) const;

 private:
  const scene::Scene* scene_;
  bool textures_ = true;
  std::vector<uint32_t> triangles_;   // area-light triangles, in scene order
  std::vector<float> cdf_;            // running power, normalised to end at 1
  std::vector<float> probability_;    // per area light: power share / area
  std::vector<uint32_t> lightOf_;     // scene triangle -> area light index, or ~0u
};

}  // namespace pr::rt
