// Shading stage: perspective-correct attribute interpolation and the metallic-roughness BRDF
// under the scene's punctual lights (no shadows). Deferred: called once per visible pixel by
// shadeRegion on the framebuffer owner, after all its triangles were rasterized, so overdraw
// costs only depth tests.
#include "raster/stages/shade.h"

#include <algorithm>
#include <cmath>
#include <numbers>

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

// Scene-triangle barycentrics from the exact edge values at a sample (shade.h).
glm::vec3 barycentricsFromEdges(const ScreenTriangle& tri, int64_t e0, int64_t e1, int64_t e2) {
  float w0 = float(e0) * tri.invW[0];
  float w1 = float(e1) * tri.invW[1];
  float w2 = float(e2) * tri.invW[2];
  float inv = 1.0f / (w0 + w1 + w2);
  glm::vec2 b = (w0 * inv) * tri.bary[0] + (w1 * inv) * tri.bary[1] + (w2 * inv) * tri.bary[2];
  return glm::vec3(1.0f - b.x - b.y, b.x, b.y);
}

glm::vec4 sampleSlot(const scene::Scene& scene, const scene::TextureRef& ref, glm::vec2 uv, bool srgb) {
  // KHR_texture_transform: the slot's matrix applied to (u, v, 1).
  glm::vec2 st(ref.uvTransform * glm::vec3(uv, 1.0f));
  return scene.textures[static_cast<size_t>(ref.texture)].sample(st, srgb);
}

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
  // Inverse-square falloff with the extension's recommended range window.
  float attenuation = 1.0f / d2;
  if (std::isfinite(light.range) && light.range > 0.0f) {
    float r = d / light.range;
    attenuation *= std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
  }
  if (light.type == scene::LightType::Spot) {
    // Smooth falloff between the cones (the extension's reference implementation).
    float cosOuter = std::cos(light.outerConeAngle);
    float cosInner = std::cos(light.innerConeAngle);
    float scale = 1.0f / std::max(0.001f, cosInner - cosOuter);
    float t = std::clamp((glm::dot(-L, light.direction) - cosOuter) * scale, 0.0f, 1.0f);
    attenuation *= t * t;
  }
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
  return sp;
}

ShadingContext makeShadingContext(const scene::Scene& scene, const FrameView& view) {
  ShadingContext ctx;
  ctx.scene = &scene;
  ctx.view = view;
  ctx.lights = scene.lights;
  ctx.usesHeadlight = ctx.lights.empty();
  return ctx;
}

namespace {

// evalBrdf's body, inlined into the per-pixel light loop.
inline glm::vec3 brdf(glm::vec3 base, float metallic, float roughness, glm::vec3 N, glm::vec3 V, glm::vec3 L) {
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
  glm::vec3 F0 = glm::mix(glm::vec3(0.04f), base, metallic);
  float f = 1.0f - VdotH;
  float f5 = f * f * f * f * f;
  glm::vec3 F = F0 + (glm::vec3(1.0f) - F0) * f5;
  glm::vec3 diffuse = ((1.0f - metallic) / kPi) * base;
  return diffuse + F * specularScale;
}

// brdf() for L = V (the headlight): then H = V, NdotH = NdotL = NdotV, VdotH = 1 and F = F0,
// which saves normalizing H. |N x V|^2 stands for 1 - NdotV^2 as in brdf().
inline glm::vec3 headlightBrdf(glm::vec3 base, float metallic, float roughness, glm::vec3 N, glm::vec3 V) {
  float r = std::max(roughness, kMinRoughness);
  float alpha = r * r;
  float alpha2 = alpha * alpha;
  float c = std::max(glm::dot(N, V), 1e-4f);
  glm::vec3 NxV = glm::cross(N, V);
  float denom = glm::dot(NxV, NxV) + c * c * alpha2;
  float k = 0.5f * alpha;
  float g = c * (1.0f - k) + k;
  float specularScale = alpha2 / (4.0f * kPi * denom * denom * g * g);
  glm::vec3 F0 = glm::mix(glm::vec3(0.04f), base, metallic);
  glm::vec3 diffuse = ((1.0f - metallic) / kPi) * base;
  return diffuse + F0 * specularScale;
}

}  // namespace

glm::vec3 evalBrdf(glm::vec3 base, float metallic, float roughness, glm::vec3 N, glm::vec3 V, glm::vec3 L) {
  return brdf(base, metallic, roughness, N, V, L);
}

glm::vec3 shadeSurface(const ShadingContext& ctx, const SurfacePoint& sp) {
  const scene::Scene& scene = *ctx.scene;
  const scene::Material& m = scene.materials[sp.material];
  glm::vec4 base = m.baseColorFactor * sp.colour;
  if (m.baseColorTexture.present()) base *= sampleSlot(scene, m.baseColorTexture, sp.uv, true);
  float metallic = m.metallicFactor, roughness = m.roughnessFactor;
  if (m.metallicRoughnessTexture.present()) {
    glm::vec4 mr = sampleSlot(scene, m.metallicRoughnessTexture, sp.uv, false);
    roughness *= mr.y;  // G channel
    metallic *= mr.z;    // B channel
  }
  glm::vec3 radiance = m.emission();
  if (m.emissiveTexture.present()) radiance *= glm::vec3(sampleSlot(scene, m.emissiveTexture, sp.uv, true));

  glm::vec3 V = ctx.view.perspective ? glm::normalize(ctx.view.eye - sp.position) : -ctx.view.forward;
  glm::vec3 albedo(base);
  if (ctx.usesHeadlight) {
    float NdotV = glm::dot(sp.normal, V);
    if (NdotV > 0.0f) radiance += headlightBrdf(albedo, metallic, roughness, sp.normal, V) * (kHeadlightLux * NdotV);
    return radiance;
  }
  for (const scene::PunctualLight& light : ctx.lights) {
    glm::vec3 L, E;
    if (!incidentLight(light, sp.position, L, E)) continue;
    float NdotL = glm::dot(sp.normal, L);
    if (NdotL <= 0.0f) continue;
    radiance += brdf(albedo, metallic, roughness, sp.normal, V, L) * E * NdotL;
  }
  return radiance;
}

void shadeRegion(const ShadingContext& ctx, std::span<const ScreenTriangle> tris, RegionFramebuffer& fb,
                 ShadeCounters* counters) {
  const Rect rect = fb.rect();
  const uint64_t* keys = fb.keys();
  const uint32_t* triangles = fb.triangles();
  glm::vec3* colours = fb.colours();
  // Neighbouring pixels mostly show the same triangle: keep its setup.
  uint32_t cached = kNoTriangle;
  EdgeFunctions s{};
  uint64_t shaded = 0;
  size_t i = 0;
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x, ++i) {
      if (!keyCovered(keys[i]) || triangles[i] == kNoTriangle) continue;
      const ScreenTriangle& tri = tris[triangles[i]];
      if (triangles[i] != cached) {
        edgeFunctions(tri, s);
        cached = triangles[i];
      }
      glm::vec3 b = barycentricsFromEdges(tri, edgeAt(s, 0, x, y), edgeAt(s, 1, x, y), edgeAt(s, 2, x, y));
      colours[i] = shadeSurface(ctx, surfaceAt(*ctx.scene, tri, b));
      ++shaded;
    }
  }
  if (counters) counters->pixelsShaded += shaded;
}

}  // namespace pr::raster
