// Shading stage, the last stage of every pipeline (deferred: after all triangles of a region
// are rasterized, each visible pixel is shaded once from the triangle that won its depth test).
// Perspective-correct attributes, the material resolved by scene::resolveMaterial (textures,
// vertex colour, normal maps: the same as the ray tracers'), the scene's punctual lights with
// Lambert plus a GGX glossy lobe under sheen and clear coat, the environment by image-based
// lighting, emission; no shadows. Runs on the PE owning the framebuffer.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene/effect_analysis.h"
#include "common/scene/light.h"
#include "common/scene/scene.h"
#include "raster/framebuffer.h"
#include "raster/stages/image_based_light.h"
#include "raster/stages/geometry.h"

namespace pr::raster {

// Attributes of the scene surface seen through one pixel sample.
struct SurfacePoint {
  glm::vec3 position{0.0f};  // world space
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  // unit; flipped towards the viewer on double-sided back faces
  glm::vec2 uv{0.0f};
  glm::vec4 colour{1.0f};    // COLOR_0, 1 when the scene has none
  glm::vec4 tangent{0.0f};   // w = handedness; zero when the scene has no normal maps
  uint32_t material = 0;
};

// Barycentrics (b0, b1, b2) of the scene triangle at the sample of pixel (x, y), interpolated
// perspective-correctly from the screen triangle: b = sum_k w_k bary_k / sum_k w_k with
// w_k = E_k / w_k (E_k the exact edge values, clip-space w_k), the hyperbolic interpolation of
// Heckbert & Moreton. Depends only on (tri, x, y).
glm::vec3 sceneBarycentrics(const ScreenTriangle& tri, int x, int y);

// The surface point of the scene triangle at those barycentrics.
SurfacePoint surfaceAt(const scene::Scene& scene, const ScreenTriangle& tri, glm::vec3 barycentrics);

// Lights, view and scene for shading one frame.
struct ShadingContext {
  const scene::Scene* scene = nullptr;
  FrameView view;
  // The scene's punctual lights, and its environment (--env, or the default light of a scene
  // without lights) through image-based lighting. A scene with neither, or one without lights
  // when the headlight is asked for, gets a headlight instead: light arriving from the eye at
  // every point (L = V) with pi lux, so that a white Lambertian surface facing the camera has
  // radiance 1. usesHeadlight says so; lights and ibl are then empty.
  std::vector<scene::PunctualLight> lights;
  std::shared_ptr<const ImageBasedLight> ibl;
  bool usesHeadlight = false;
  // Some material is alpha-cut (MASK or BLEND): rasterization tests its fragments' alpha.
  bool alphaTested = false;
  // The RenderPlan's effects (common/scene/effect_analysis.h) this stage can skip: textures off
  // shades from the material factors, emission off adds no emitted radiance, direct off adds
  // no light (punctual or headlight) and none of the environment's on the diffuse and sheen
  // lobes. The environment's reflection follows the switches of the ray tracers' reflection
  // rays that would see it: specular for a mirror-smooth base lobe (roughness below
  // scene::kIdealSpecularRoughness), glossy for a rougher one and for the clear coat. The work
  // not done is counted in ShadeCounters.
  bool textures = true, emission = true, direct = true, specular = true, glossy = true;
  // Pixels per SIMD step of the headlit kernel: 8 (AVX2) or 4 (SSE2), chosen once per run for
  // the processor (shadeLanes()); either gives the same bits.
  int lanes = 4;
};

// Whether the rasterizer lights this scene by its headlight: it has no punctual lights, and
// no environment or --headlight asked for.
bool litByHeadlight(const scene::Scene& scene, bool headlight);

ShadingContext makeShadingContext(const scene::Scene& scene, const FrameView& view,
                                  scene::EffectSet effects = scene::EffectSet::all(), bool headlight = false);

// BRDF value f_r(V, L) for the metallic-roughness model (glTF 2.0, Appendix B): Lambert
// (1 - metallic) * base / pi plus the Cook-Torrance lobe D G F / (4 NdotL NdotV) with the GGX
// distribution (alpha = roughness^2), Schlick-GGX geometry (k = alpha/2) and Schlick Fresnel
// from F0 = mix(f0, base, metallic) to F90 = mix(f90, 1, metallic), f0 and f90 the dielectric's
// (0.04 and 1 in the core model; KHR_materials_specular changes them). N, V, L are unit vectors.
glm::vec3 evalBrdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 N, glm::vec3 V, glm::vec3 L,
                   glm::vec3 f0 = glm::vec3(0.04f), float f90 = 1.0f);

struct ShadeCounters {
  uint64_t pixelsShaded = 0;
  // The plan's skipped work (the Plan/ counters of the run record, as the ray tracers name it).
  uint64_t textureEvaluationsSkipped = 0;  // texture lookups not made (textures off)
  uint64_t lightSamplesSkipped = 0;        // light evaluations not made (direct off), headlight included
  uint64_t emissionSkipped = 0;            // emissive pixels whose emission was not added
  ShadeCounters& operator+=(const ShadeCounters& o) {
    pixelsShaded += o.pixelsShaded;
    textureEvaluationsSkipped += o.textureEvaluationsSkipped;
    lightSamplesSkipped += o.lightSamplesSkipped;
    emissionSkipped += o.emissionSkipped;
    return *this;
  }
};

// Outgoing radiance towards the camera: emission + sum over lights of f_r * E * cos(theta),
// less what the plan turned off (counted in counters when given).
glm::vec3 shadeSurface(const ShadingContext& ctx, const SurfacePoint& point, ShadeCounters* counters = nullptr);

// Pixels per SIMD step of the headlit kernel on this processor: 8 where it has AVX2, else 4.
int shadeLanes();

// Shades every covered pixel of the window from tris[triangle index there] (the list it was
// rasterized from) and writes its colour. Uncovered pixels keep the background colour 0.
void shadeRegion(const ShadingContext& ctx, std::span<const ScreenTriangle> tris, const PixelWindow& pixels,
                 ShadeCounters* counters = nullptr);

// The same over a whole framebuffer.
inline void shadeRegion(const ShadingContext& ctx, std::span<const ScreenTriangle> tris, RegionFramebuffer& fb,
                        ShadeCounters* counters = nullptr) {
  shadeRegion(ctx, tris, fb.window(), counters);
}

}  // namespace pr::raster
