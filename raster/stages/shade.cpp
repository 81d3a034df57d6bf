// Shading stage: perspective-correct attribute interpolation and the metallic-roughness BRDF
// under the scene's punctual lights (no shadows). Deferred: called once per visible pixel by
// shadeRegion on the framebuffer owner, after all its triangles were rasterized, so overdraw
// costs only depth tests. Headlit untextured pixels go through SIMD lanes (shade_lanes.inc:
// eight AVX2 lanes where the processor has them, else four SSE lanes), each lane repeating the
// scalar operations exactly, so the images do not change.
#include "raster/stages/shade.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "common/scene/material_layers.h"
#include "common/util/cpu_features.h"
#include "common/util/error.h"
#include "common/scene/surface_material.h"
#include "common/scene/texture.h"
#include "raster/framebuffer.h"
#include "raster/stages/setup.h"

namespace pr::raster {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
// Roughness below this makes the GGX lobe narrower than a pixel's worth of directions and the
// highlight of a point light a single-sample spike (Filament's clamp, 0.045).
constexpr float kMinRoughness = 0.045f;
// Headlight irradiance: pi lux makes a white Lambertian surface facing the camera radiance 1.
constexpr float kHeadlightLux = kPi;

// Irradiance at normal incidence (lux) and direction towards the light, KHR_lights_punctual.
bool incidentLight(const scene::PunctualLight& light, glm::vec3 p, glm::vec3& L, glm::vec3& E) {
  if (light.type == scene::LightType::Directional) {
    L = -light.direction;
    E = light.color * light.intensity;
    return true;
  }
  glm::vec3 toLight = light.position - p;
  float d2 = glm::dot(toLight, toLight);
  if (!(d2 > 0.0f)) return false;
  float d = std::sqrt(d2);
  L = toLight / d;
  // Inverse-square falloff with the extension's range window and spot cone (common/scene/light.h).
  float attenuation = scene::rangeWindow(d, light.range) / d2;
  if (light.type == scene::LightType::Spot) attenuation *= scene::spotFactor(light, -L);
  E = light.color * (light.intensity * attenuation);
  return attenuation > 0.0f;
}

}  // namespace

glm::vec3 sceneBarycentrics(const ScreenTriangle& tri, int x, int y) {
  TriangleSetup s;
  if (!setupTriangle(tri, s)) return glm::vec3(1.0f, 0.0f, 0.0f);
  return barycentricsFromEdges(tri, edgeAt(s, 0, x, y), edgeAt(s, 1, x, y), edgeAt(s, 2, x, y));
}

SurfacePoint surfaceAt(const scene::Scene& scene, const ScreenTriangle& tri, glm::vec3 b) {
  const scene::Triangle& t = scene.triangles[tri.primitive];
  SurfacePoint sp;
  sp.material = t.material;
  const glm::vec3& p0 = scene.positions[t.v[0]];
  const glm::vec3& p1 = scene.positions[t.v[1]];
  const glm::vec3& p2 = scene.positions[t.v[2]];
  sp.position = b.x * p0 + b.y * p1 + b.z * p2;
  glm::vec3 n;
  if (!scene.normals.empty()) {
    n = b.x * scene.normals[t.v[0]] + b.y * scene.normals[t.v[1]] + b.z * scene.normals[t.v[2]];
  } else {
    n = glm::cross(p1 - p0, p2 - p0);
  }
  float len2 = glm::dot(n, n);
  // A degenerate normal (opposite vertex normals, zero-area triangle) falls back to +z rather
  // than becoming NaN.
  sp.normal = len2 > 0.0f ? n / std::sqrt(len2) : glm::vec3(0.0f, 0.0f, 1.0f);
  if (tri.backFacing) sp.normal = -sp.normal;
  if (!scene.uvs.empty()) sp.uv = b.x * scene.uvs[t.v[0]] + b.y * scene.uvs[t.v[1]] + b.z * scene.uvs[t.v[2]];
  if (!scene.colors.empty()) {
    sp.colour = b.x * scene.colors[t.v[0]] + b.y * scene.colors[t.v[1]] + b.z * scene.colors[t.v[2]];
  }
  if (!scene.tangents.empty()) {
    const glm::vec4 t0 = scene.tangents[t.v[0]];
    glm::vec3 tangent = b.x * glm::vec3(t0) + b.y * glm::vec3(scene.tangents[t.v[1]]) + b.z * glm::vec3(scene.tangents[t.v[2]]);
    // A back face seen through double-sidedness mirrors the frame: the bitangent flips with it.
    sp.tangent = glm::vec4(tangent, tri.backFacing ? -t0.w : t0.w);
  }
  return sp;
}

bool litByHeadlight(const scene::Scene& scene, bool headlight) {
  return scene.lights.empty() && (headlight || !scene.environment);
}

ShadingContext makeShadingContext(const scene::Scene& scene, const FrameView& view, scene::EffectSet effects,
                                  bool headlight) {
  ShadingContext ctx;
  ctx.scene = &scene;
  ctx.view = view;
  ctx.lights = scene.lights;
  ctx.usesHeadlight = litByHeadlight(scene, headlight);
  if (!ctx.usesHeadlight) ctx.ibl = ImageBasedLight::of(scene.environment);
  ctx.alphaTested = std::any_of(scene.materials.begin(), scene.materials.end(),
                                [](const scene::Material& m) { return scene::alphaCuts(m); });
  ctx.textures = effects.has(scene::Effect::Textures);
  ctx.emission = effects.has(scene::Effect::Emission);
  ctx.direct = effects.has(scene::Effect::DirectLight);
  ctx.specular = effects.has(scene::Effect::IdealSpecular);
  ctx.glossy = effects.has(scene::Effect::GlossySpecular);
  ctx.lanes = shadeLanes();
  return ctx;
}

namespace {

float maxComponent(const glm::vec3& c) { return std::max(c.x, std::max(c.y, c.z)); }

// What the dielectric's Fresnel layer leaves the diffuse part under it (the glTF spec's
// fresnel_mix): 1 - max(F), F the layer's Schlick term for the light's half-vector.
inline float diffuseUnderLayer(glm::vec3 dielectricF0, float dielectricF90, float f5) {
  return 1.0f - maxComponent(dielectricF0 + (glm::vec3(dielectricF90) - dielectricF0) * f5);
}

// evalBrdf's body, inlined into the per-pixel light loop.
inline glm::vec3 brdf(glm::vec3 base, float metallic, float roughness, glm::vec3 N, glm::vec3 V, glm::vec3 L,
                      glm::vec3 dielectricF0, float dielectricF90) {
  float NdotL = std::max(glm::dot(N, L), 0.0f);
  if (NdotL <= 0.0f) return glm::vec3(0.0f);
  // Interpolated normals can face slightly away from the eye at silhouettes; keep NdotV > 0.
  float NdotV = std::max(glm::dot(N, V), 1e-4f);
  glm::vec3 H = V + L;
  float hLen2 = glm::dot(H, H);
  H = hLen2 > 0.0f ? H / std::sqrt(hLen2) : N;
  float NdotH = std::max(glm::dot(N, H), 0.0f);
  float VdotH = std::max(glm::dot(V, H), 0.0f);

  float r = std::max(roughness, kMinRoughness);
  float alpha = r * r;
  float alpha2 = alpha * alpha;
  // GGX: D = alpha^2 / (pi ((NdotH^2 (alpha^2 - 1) + 1)^2); the bracket written as
  // |N x H|^2 + (NdotH alpha)^2 (1 - NdotH^2 = |N x H|^2) avoids cancelling 1 against 1 - tiny
  // for smooth surfaces near the highlight centre.
  glm::vec3 NxH = glm::cross(N, H);
  float denom = glm::dot(NxH, NxH) + NdotH * NdotH * alpha2;
  // Schlick-GGX: G = G1(L) G1(V), G1(x) = x / (x (1 - k) + k). The x factors of G cancel the
  // 1 / (4 NdotL NdotV) of Cook-Torrance, leaving one division for D G / (4 NdotL NdotV).
  float k = 0.5f * alpha;
  float gl = NdotL * (1.0f - k) + k;
  float gv = NdotV * (1.0f - k) + k;
  float specularScale = alpha2 / (4.0f * kPi * denom * denom * gl * gv);
  glm::vec3 F0 = glm::mix(dielectricF0, base, metallic);
  float F90 = dielectricF90 + (1.0f - dielectricF90) * metallic;
  float f = 1.0f - VdotH;
  float f5 = f * f * f * f * f;
  glm::vec3 F = F0 + (glm::vec3(F90) - F0) * f5;
  glm::vec3 diffuse = ((1.0f - metallic) * diffuseUnderLayer(dielectricF0, dielectricF90, f5) / kPi) * base;
  return diffuse + F * specularScale;
}

// The headlight's diffuse term: brdf()'s at VdotH = 1, where the layer's Fresnel term is its F0.
inline glm::vec3 headlightDiffuse(glm::vec3 base, float metallic, glm::vec3 dielectricF0) {
  return ((1.0f - metallic) * (1.0f - maxComponent(dielectricF0)) / kPi) * base;
}

// brdf() for L = V (the headlight): then H = V, NdotH = NdotL = NdotV, VdotH = 1 and F = F0,
// which saves normalizing H. |N x V|^2 stands for 1 - NdotV^2 as in brdf().
inline glm::vec3 headlightBrdf(glm::vec3 base, float metallic, float roughness, glm::vec3 N, glm::vec3 V,
                               glm::vec3 dielectricF0) {
  float r = std::max(roughness, kMinRoughness);
  float alpha = r * r;
  float alpha2 = alpha * alpha;
  float c = std::max(glm::dot(N, V), 1e-4f);
  glm::vec3 NxV = glm::cross(N, V);
  float denom = glm::dot(NxV, NxV) + c * c * alpha2;
  float k = 0.5f * alpha;
  float g = c * (1.0f - k) + k;
  float specularScale = alpha2 / (4.0f * kPi * denom * denom * g * g);
  glm::vec3 F0 = glm::mix(dielectricF0, base, metallic);
  return headlightDiffuse(base, metallic, dielectricF0) + F0 * specularScale;
}

}  // namespace

glm::vec3 evalBrdf(glm::vec3 base, float metallic, float roughness, glm::vec3 N, glm::vec3 V, glm::vec3 L, glm::vec3 f0,
                   float f90) {
  return brdf(base, metallic, roughness, N, V, L, f0, f90);
}

namespace {

// f_r cos for light arriving from L: the base BRDF, then sheen over it and the clear coat on
// top (common/scene/material_layers.h), each layer with the cosine of its own normal.
glm::vec3 layeredLight(const scene::SurfaceMaterial& r, glm::vec3 V, glm::vec3 L) {
  const glm::vec3 N = r.normal;
  const float NdotL = glm::dot(N, L);
  glm::vec3 out(0.0f);
  if (NdotL > 0.0f) {
    glm::vec3 f = brdf(r.baseColor, r.metallic, r.roughness, N, V, L, r.dielectricF0(), r.dielectricF90());
    if (r.hasSheen()) {
      const float NdotV = std::max(glm::dot(N, V), 1e-4f);
      const float NdotH = glm::dot(N, glm::normalize(V + L));
      const float scale = 1.0f - maxComponent(r.sheenColor) * std::max(scene::sheenAlbedo(r.sheenRoughness, NdotV),
                                                                        scene::sheenAlbedo(r.sheenRoughness, NdotL));
      f = f * scale + r.sheenColor * scene::sheenLobe(r.sheenRoughness, NdotH, NdotL, NdotV);
    }
    out = f * NdotL;
  }
  if (r.clearcoat > 0.0f) {
    const glm::vec3& C = r.clearcoatNormal;
    const float CdotV = std::max(glm::dot(C, V), 1e-4f), CdotL = glm::dot(C, L);
    out *= 1.0f - r.clearcoat * scene::coatFresnel(CdotV);
    if (CdotL > 0.0f) {
      const glm::vec3 H = glm::normalize(V + L);
      out += glm::vec3(r.clearcoat * scene::coatLobe(r.clearcoatRoughness, glm::dot(C, H), CdotL, CdotV, glm::dot(V, H)) * CdotL);
    }
  }
  return out;
}

// Which lobes of the environment's light the plan keeps (ShadingContext's switches).
struct EnvironmentLobes {
  bool diffuse, reflection, coat;
};

// Radiance reflected from the environment by image-based lighting: diffuse from the SH
// irradiance, specular by the split sum, sheen and clear coat layered as under a light. A lobe
// the plan turns off adds nothing; the layers still scale what is under them.
glm::vec3 environmentLight(const ImageBasedLight& ibl, const scene::SurfaceMaterial& r, glm::vec3 V, EnvironmentLobes on) {
  const glm::vec3 N = r.normal;
  const float NdotV = std::max(glm::dot(N, V), 1e-4f);
  const glm::vec3 irradiance = ibl.irradiance(N);
  const float roughness = std::max(r.roughness, kMinRoughness);
  const glm::vec2 ab = specularAlbedo(NdotV, roughness);
  const glm::vec3 F0 = glm::mix(r.dielectricF0(), r.baseColor, r.metallic);
  const float F90 = r.dielectricF90() + (1.0f - r.dielectricF90()) * r.metallic;
  const glm::vec3 R = 2.0f * glm::dot(N, V) * N - V;
  // The diffuse part less the dielectric layer's directional albedo (the split sum's), as the
  // Fresnel layer takes it off under a light.
  const float underLayer = 1.0f - maxComponent(r.dielectricF0() * ab.x + glm::vec3(r.dielectricF90() * ab.y));
  const glm::vec3 diffuse =
      on.diffuse ? ((1.0f - r.metallic) * underLayer / kPi) * r.baseColor * irradiance : glm::vec3(0.0f);
  glm::vec3 out = on.reflection ? diffuse + ibl.prefiltered(R, roughness) * (F0 * ab.x + F90 * ab.y) : diffuse;
  if (r.hasSheen()) {
    const float albedo = scene::sheenAlbedo(r.sheenRoughness, NdotV);
    const glm::vec3 sheen = on.diffuse ? r.sheenColor * (albedo / kPi) * irradiance : glm::vec3(0.0f);
    out = out * (1.0f - maxComponent(r.sheenColor) * albedo) + sheen;
  }
  if (r.clearcoat > 0.0f) {
    const glm::vec3& C = r.clearcoatNormal;
    const float CdotV = std::max(glm::dot(C, V), 1e-4f);
    const float coatRoughness = std::max(r.clearcoatRoughness, kMinRoughness);
    const glm::vec2 abc = specularAlbedo(CdotV, coatRoughness);
    const glm::vec3 Rc = 2.0f * glm::dot(C, V) * C - V;
    const glm::vec3 coat = on.coat ? r.clearcoat * ibl.prefiltered(Rc, coatRoughness) * (0.04f * abc.x + abc.y) : glm::vec3(0.0f);
    out = out * (1.0f - r.clearcoat * scene::coatFresnel(CdotV)) + coat;
  }
  return out;
}

}  // namespace

glm::vec3 shadeSurface(const ShadingContext& ctx, const SurfacePoint& sp, ShadeCounters* counters) {
  const scene::Scene& scene = *ctx.scene;
  const scene::Material& m = scene.materials[sp.material];
  // Textures the plan skips are counted, and the factors alone used.
  const scene::SurfaceMaterial r = scene::resolveMaterial(scene, sp.material, {sp.uv, sp.colour, sp.normal, sp.tangent},
                                                          ctx.textures, counters ? &counters->textureEvaluationsSkipped : nullptr);
  glm::vec3 radiance(0.0f);
  if (ctx.emission) {
    radiance = r.emission;
  } else if (counters && m.isEmissive()) {
    ++counters->emissionSkipped;
  }
  // The environment's reflection of this material: a mirror-smooth base lobe is the plan's
  // specular, a rougher one its glossy (the ray tracers' reflection rays).
  const bool mirrorLike = r.roughness < scene::kIdealSpecularRoughness;
  const EnvironmentLobes lobes{ctx.direct, mirrorLike ? ctx.specular : ctx.glossy, ctx.glossy};
  if (!ctx.direct) {
    // The lights, and the environment's diffuse and sheen light, are skipped.
    if (counters) counters->lightSamplesSkipped += (ctx.usesHeadlight ? 1 : ctx.lights.size()) + (ctx.ibl ? 1 : 0);
    if (!ctx.ibl || !(lobes.reflection || lobes.coat)) return radiance;
  }

  glm::vec3 V = ctx.view.perspective ? glm::normalize(ctx.view.eye - sp.position) : -ctx.view.forward;
  if (!ctx.direct) return radiance + environmentLight(*ctx.ibl, r, V, lobes);
  if (ctx.usesHeadlight) {
    // Without layers, headlightBrdf: the exact operations of the SSE lanes (shadeBatch).
    const float NdotV = glm::dot(r.normal, V);
    if (r.hasSheen() || r.clearcoat > 0.0f) radiance += layeredLight(r, V, V) * kHeadlightLux;
    else if (NdotV > 0.0f)
      radiance += headlightBrdf(r.baseColor, r.metallic, r.roughness, r.normal, V, r.dielectricF0()) * (kHeadlightLux * NdotV);
    return radiance;
  }
  for (const scene::PunctualLight& light : ctx.lights) {
    glm::vec3 L, E;
    if (incidentLight(light, sp.position, L, E)) radiance += layeredLight(r, V, L) * E;
  }
  if (ctx.ibl) radiance += environmentLight(*ctx.ibl, r, V, lobes);
  return radiance;
}

namespace {

// ---- Several pixels at a time -------------------------------------------------------------
// The common case (headlight, untextured materials, no vertex colours) is shaded in SIMD lanes
// (shade_lanes.inc); what the lanes need of a triangle and a material is computed here.

// Shading constants of one material under the headlight (headlightBrdf's per-material terms).
struct HeadlightMaterial {
  bool fast = false;  // no texture slot: every term below is a constant of the material
  float alpha2 = 0.0f, k = 0.0f, oneMinusK = 0.0f;
  glm::vec3 f0{0.0f}, diffuse{0.0f}, emission{0.0f};
};

HeadlightMaterial headlightMaterial(const scene::Scene& scene, uint32_t id) {
  const scene::Material& m = scene.materials[id];
  HeadlightMaterial h;
  h.fast = !scene::usesTextures(m) && !m.hasSheen() && !m.hasClearcoat();
  // As shadeSurface and headlightBrdf compute them (sp.colour = 1 without vertex colours).
  const scene::SurfaceMaterial r = scene::resolveMaterial(scene, id, {});
  float rough = std::max(r.roughness, kMinRoughness);
  float alpha = rough * rough;
  h.alpha2 = alpha * alpha;
  h.k = 0.5f * alpha;
  h.oneMinusK = 1.0f - h.k;
  h.f0 = glm::mix(r.dielectricF0(), r.baseColor, r.metallic);
  h.diffuse = headlightDiffuse(r.baseColor, r.metallic, r.dielectricF0());
  h.emission = r.emission;
  return h;
}

// The fields of one triangle's lane inputs: what barycentrics, surface point and BRDF read.
enum Field : int {
  kInvW0, kInvW1, kInvW2,
  kBary0X, kBary0Y, kBary1X, kBary1Y, kBary2X, kBary2Y,
  kP0X, kP0Y, kP0Z, kP1X, kP1Y, kP1Z, kP2X, kP2Y, kP2Z,
  // Vertex normals, or (without them) the triangle's finished face normal in kN0*.
  kN0X, kN0Y, kN0Z, kN1X, kN1Y, kN1Z, kN2X, kN2Y, kN2Z,
  kBack, kAlpha2, kK, kOneMinusK, kF0X, kF0Y, kF0Z, kDiffX, kDiffY, kDiffZ, kEmitX, kEmitY, kEmitZ,
  kTriangleFields
};

// The lane fields of one screen triangle: its vertices' attributes and its material's constants.
void triangleFields(const scene::Scene& scene, const ScreenTriangle& tri, const HeadlightMaterial& hm,
                    float* out) {
  const scene::Triangle& t = scene.triangles[tri.primitive];
  float* o = out;
  for (int k = 0; k < 3; ++k) *o++ = tri.invW[k];
  for (int k = 0; k < 3; ++k) {
    *o++ = tri.bary[k].x;
    *o++ = tri.bary[k].y;
  }
  for (int k = 0; k < 3; ++k) {
    const glm::vec3& p = scene.positions[t.v[k]];
    *o++ = p.x;
    *o++ = p.y;
    *o++ = p.z;
  }
  if (!scene.normals.empty()) {
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& n = scene.normals[t.v[k]];
      *o++ = n.x;
      *o++ = n.y;
      *o++ = n.z;
    }
  } else {
    // surfaceAt's face normal, finished once per triangle.
    const glm::vec3& p0 = scene.positions[t.v[0]];
    glm::vec3 n = glm::cross(scene.positions[t.v[1]] - p0, scene.positions[t.v[2]] - p0);
    float len2 = glm::dot(n, n);
    n = len2 > 0.0f ? n / std::sqrt(len2) : glm::vec3(0.0f, 0.0f, 1.0f);
    if (tri.backFacing) n = -n;
    for (int k = 0; k < 9; ++k) *o++ = k < 3 ? n[k] : 0.0f;
  }
  *o++ = tri.backFacing ? 1.0f : 0.0f;
  *o++ = hm.alpha2;
  *o++ = hm.k;
  *o++ = hm.oneMinusK;
  for (int k = 0; k < 3; ++k) *o++ = hm.f0[k];
  for (int k = 0; k < 3; ++k) *o++ = hm.diffuse[k];
  for (int k = 0; k < 3; ++k) *o++ = hm.emission[k];
}

namespace sse {
#define PR_SHADE_LANES 4
#include "raster/stages/shade_lanes.inc"
#undef PR_SHADE_LANES
}  // namespace sse

// The same kernel eight lanes wide, compiled for AVX2 (and only run where the processor has
// it). Everything it defines has internal linkage, so no AVX code reaches other callers.
PR_BEGIN_AVX2
namespace avx2 {
#define PR_SHADE_LANES 8
#include "raster/stages/shade_lanes.inc"
#undef PR_SHADE_LANES
}  // namespace avx2
PR_END_AVX2

}  // namespace

int shadeLanes() { return hasAvx2() ? avx2::kLanes : sse::kLanes; }

void shadeRegion(const ShadingContext& ctx, std::span<const ScreenTriangle> tris, const PixelWindow& fb,
                 ShadeCounters* counters) {
  PR_CHECK(ctx.lanes == sse::kLanes || (ctx.lanes == avx2::kLanes && hasAvx2()),
           "shadeRegion: no kernel of that many lanes on this processor");
  if (ctx.lanes == avx2::kLanes) avx2::shadeRegionLanes(ctx, tris, fb, counters);
  else sse::shadeRegionLanes(ctx, tris, fb, counters);
}

}  // namespace pr::raster
