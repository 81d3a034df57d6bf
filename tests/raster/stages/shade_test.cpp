// Tests of the shading stage: perspective-correct interpolation against ray casting, the BRDF
// and the rendered radiance against closed forms, point-light falloff, double-sided back
// faces, emission, and base-colour textures with the sampler's wrap mode.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "raster/sequential_pipeline.h"
#include "raster/stages/shade.h"
#include "raster/raster_test_scenes.h"

namespace pr::raster {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

bool near(glm::vec3 a, glm::vec3 b, float relTol) {
  glm::vec3 d = glm::abs(a - b);
  float scale = std::max({std::abs(b.x), std::abs(b.y), std::abs(b.z), 1e-6f});
  return d.x <= relTol * scale && d.y <= relTol * scale && d.z <= relTol * scale;
}

TEST_CASE("Shade: perspective-correct interpolation matches ray casting") {
  constexpr int kW = 64, kH = 48;
  constexpr double kFov = 0.9;
  scene::Scene s = test::emptyScene();
  // A triangle receding steeply in depth (z from -2 to -14), so screen-linear interpolation is
  // visibly wrong; uv = the barycentrics (b1, b2).
  glm::dvec3 a(-3, -2, -2), b(3, -2, -14), c(0, 3, -6);
  test::addTriangle(s, glm::vec3(a), glm::vec3(b), glm::vec3(c));
  s.uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
  FrameView view = makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}, float(kFov)), kW, kH);
  std::vector<ScreenTriangle> tris;
  processTriangles(s, view, 0, 1, tris);
  REQUIRE(tris.size() == 1);
  ScreenTriangle affine = tris[0];
  for (float& w : affine.invW) w = 1.0f;

  glm::dvec3 n = glm::cross(b - a, c - a);
  double worst = 0.0, worstAffine = 0.0;
  int checked = 0;
  auto counts = test::coverageCounts(kW, kH, tris);
  for (int j = 0; j < kH; ++j) {
    for (int i = 0; i < kW; ++i) {
      if (counts[size_t(j) * kW + i] == 0) continue;
      double t = std::tan(kFov / 2.0);
      glm::dvec3 d(((i + 0.5) / kW * 2.0 - 1.0) * t * kW / kH, (1.0 - (j + 0.5) / kH * 2.0) * t, -1.0);
      glm::dvec3 p = d * (glm::dot(n, a) / glm::dot(n, d));
      // Analytic barycentrics of the hit point.
      double b1 = glm::dot(glm::cross(p - a, c - a), n) / glm::dot(n, n);
      double b2 = glm::dot(glm::cross(b - a, p - a), n) / glm::dot(n, n);
      glm::vec3 bary = sceneBarycentrics(tris[0], i, j);
      SurfacePoint sp = surfaceAt(s, tris[0], bary);
      worst = std::max({worst, std::abs(sp.uv.x - b1), std::abs(sp.uv.y - b2)});
      glm::vec3 flat = sceneBarycentrics(affine, i, j);
      worstAffine = std::max({worstAffine, std::abs(flat.y - b1), std::abs(flat.z - b2)});
      ++checked;
    }
  }
  CHECK(checked > 200);
  // Snapping moves each vertex up to 1/512 px; over edges of 20-40 px that shifts barycentrics
  // by about 1e-4 (more where w is large), float evaluation adds ~1e-6: bound 5e-4.
  CHECK(worst < 5e-4);
  // The check is sensitive: affine interpolation is off by far more.
  CHECK(worstAffine > 0.05);
}

TEST_CASE("Shade: BRDF at normal incidence matches the closed form") {
  glm::vec3 n(0.0f, 0.0f, 1.0f);
  glm::vec3 base(0.8f, 0.5f, 0.2f);
  // V = L = N: H = N, D = 1 / (pi alpha^2), G = 1, F = F0, so
  // f = (1 - m)(1 - 0.04) base / pi + F0 / (4 pi alpha^2), F0 = mix(0.04, base, m): the
  // diffuse part loses what the dielectric's 4 % layer reflects (the spec's fresnel_mix).
  for (float metallic : {0.0f, 0.3f, 1.0f}) {
    for (float roughness : {1.0f, 0.5f, 0.2f}) {
      float alpha = roughness * roughness;
      glm::vec3 f0 = glm::mix(glm::vec3(0.04f), base, metallic);
      glm::vec3 expected = (1.0f - metallic) * (1.0f - 0.04f) * base / kPi + f0 / (4.0f * kPi * alpha * alpha);
      CAPTURE(metallic);
      CAPTURE(roughness);
      CHECK(near(evalBrdf(base, metallic, roughness, n, n, n), expected, 1e-5f));
    }
  }
  // Light below the surface contributes nothing.
  CHECK(evalBrdf(base, 0.0f, 1.0f, n, n, -n) == glm::vec3(0.0f));
}

TEST_CASE("Shade: a lit plane renders the analytic radiance") {
  // Orthographic camera looking down -z at a plane facing it, a directional light of E lux
  // shining straight down the view: radiance = f_r(N, N, N) * E (the closed form above).
  scene::Scene s = test::emptyScene();
  s.materials[0].baseColorFactor = glm::vec4(0.5f, 0.25f, 1.0f, 1.0f);
  s.materials[0].metallicFactor = 0.0f;
  s.materials[0].roughnessFactor = 1.0f;
  test::addTriangle(s, {-20, -20, 0}, {20, -20, 0}, {20, 20, 0});
  test::addTriangle(s, {-20, -20, 0}, {20, 20, 0}, {-20, 20, 0});
  scene::PunctualLight sun;
  sun.type = scene::LightType::Directional;
  sun.direction = glm::vec3(0.0f, 0.0f, -1.0f);
  sun.intensity = 3.0f;
  s.lights.push_back(sun);
  RasterStats stats;
  RegionFramebuffer fb = renderSequential(s, test::pixelOrthoCamera(16), 16, 16, {}, &stats);
  CHECK_FALSE(stats.usesHeadlight);
  glm::vec3 base(0.5f, 0.25f, 1.0f);
  glm::vec3 expected = 3.0f * (0.96f * base / kPi + glm::vec3(0.04f) / (4.0f * kPi));
  CHECK(fb.coveredPixels() == 16 * 16);
  CHECK(near(fb.colour(3, 5), expected, 1e-5f));
  CHECK(near(fb.colour(15, 0), expected, 1e-5f));
}

TEST_CASE("Shade: point lights fall off with the inverse square and the range window") {
  scene::Scene s = test::emptyScene();
  scene::PunctualLight bulb;
  bulb.type = scene::LightType::Point;
  bulb.position = glm::vec3(0.0f, 0.0f, 4.0f);
  bulb.intensity = 10.0f;
  s.lights.push_back(bulb);
  ShadingContext ctx = makeShadingContext(s, makeFrameView(test::pixelOrthoCamera(16), 16, 16));
  SurfacePoint sp;
  sp.normal = glm::vec3(0.0f, 0.0f, 1.0f);
  sp.position = glm::vec3(0.0f, 0.0f, 3.0f);  // 1 unit below the light
  glm::vec3 at1 = shadeSurface(ctx, sp);
  sp.position = glm::vec3(0.0f, 0.0f, 2.0f);  // 2 units
  glm::vec3 at2 = shadeSurface(ctx, sp);
  // Same directions (V = L = N), so the ratio is exactly the inverse square law.
  CHECK(near(at1, 4.0f * at2, 1e-5f));
  CHECK(near(at1, 10.0f * evalBrdf(glm::vec3(1.0f), 0.0f, 1.0f, sp.normal, sp.normal, sp.normal), 1e-5f));
  // Beyond its range a light contributes nothing; at half range the window is (1 - (1/2)^4)^2,
  // the same window the ray tracers apply.
  ctx.lights[0].range = 1.5f;
  CHECK(shadeSurface(ctx, sp) == glm::vec3(0.0f));
  ctx.lights[0].range = 4.0f;
  CHECK(near(shadeSurface(ctx, sp), at2 * (1.0f - 1.0f / 16.0f) * (1.0f - 1.0f / 16.0f), 1e-5f));
}

TEST_CASE("Shade: double-sided back faces are lit on the viewer's side, emission adds") {
  scene::Scene s = test::emptyScene();
  s.materials[0].doubleSided = true;
  scene::Material glow = s.materials[0];
  glow.emissiveFactor = glm::vec3(1.0f, 0.5f, 0.0f);
  glow.emissiveStrength = 2.0f;
  s.materials.push_back(glow);
  // Left half: a back face (clockwise from the camera); right half: the same, emissive.
  test::addTriangle(s, {-8, -8, 0}, {0, 8, 0}, {0, -8, 0}, 0);
  test::addTriangle(s, {0, -8, 0}, {8, 8, 0}, {8, -8, 0}, 1);
  RasterStats stats;
  RegionFramebuffer fb = renderSequential(s, test::pixelOrthoCamera(16), 16, 16, {}, &stats);
  CHECK(stats.usesHeadlight);
  // The headlight (pi lux down the view) on a white diffuse surface under the 4% glossy layer,
  // facing the camera after the normal flip: the diffuse part less the layer's 4 %, plus 0.01.
  glm::vec3 lit(0.96f + 0.04f / 4.0f);
  CHECK(near(fb.colour(4, 10), lit, 1e-5f));
  CHECK(near(fb.colour(12, 12), lit + glm::vec3(2.0f, 1.0f, 0.0f), 1e-5f));
}

TEST_CASE("Shade: without punctual lights a headlight at the eye lights by cos(N, V)") {
  scene::Scene s = test::emptyScene();
  FrameView view = makeFrameView(test::lookAtCamera({0, 0, 0}, {0, 0, -1}), 16, 16);
  ShadingContext ctx = makeShadingContext(s, view);
  CHECK(ctx.usesHeadlight);
  // A floor point 1 below and 1 ahead of the eye: V = (0, 1, 1)/sqrt 2, N = +y, cos = 1/sqrt 2.
  SurfacePoint sp;
  sp.position = glm::vec3(0.0f, -1.0f, -1.0f);
  sp.normal = glm::vec3(0.0f, 1.0f, 0.0f);
  glm::vec3 V = glm::normalize(glm::vec3(0.0f, 1.0f, 1.0f));
  glm::vec3 expected = evalBrdf(glm::vec3(1.0f), 0.0f, 1.0f, sp.normal, V, V) * (kPi * V.y);
  CHECK(near(shadeSurface(ctx, sp), expected, 1e-5f));
  CHECK(shadeSurface(ctx, sp).x > 0.5f);
  // A smooth metal seen 2 degrees off its normal (the narrow GGX peak) agrees with the general
  // BRDF evaluated for L = V.
  s.materials[0].metallicFactor = 1.0f;
  s.materials[0].roughnessFactor = 0.05f;
  sp.normal = glm::normalize(V + glm::vec3(0.035f, 0.0f, 0.0f));
  glm::vec3 smooth = evalBrdf(glm::vec3(1.0f), 1.0f, 0.05f, sp.normal, V, V) * (kPi * glm::dot(sp.normal, V));
  CHECK(near(shadeSurface(ctx, sp), smooth, 1e-4f));
  // Facing away from the eye: unlit.
  sp.normal = -sp.normal;
  CHECK(shadeSurface(ctx, sp) == glm::vec3(0.0f));
}

TEST_CASE("Shade: base colour textures use the sampler's wrap mode and bilinear filter") {
  scene::Scene s = test::emptyScene();
  scene::Texture tex;
  tex.width = 2;
  tex.height = 1;
  tex.rgba8 = {255, 0, 0, 255, 0, 255, 0, 255};  // red, green
  tex.sampler.magFilter = scene::Filter::Nearest;
  s.textures.push_back(tex);
  s.materials[0].baseColorTexture.texture = 0;
  ShadingContext ctx = makeShadingContext(s, makeFrameView(test::pixelOrthoCamera(16), 16, 16));
  SurfacePoint sp;
  sp.position = glm::vec3(0.0f);
  sp.normal = glm::vec3(0.0f, 0.0f, 1.0f);
  // Headlight of pi lux, V = L = N: radiance = 0.96 base + 0.01 (the diffuse part under the 4%
  // glossy layer, which adds 0.01 white).
  // u = 1.25 is texel 2.5 -> texel 0 (red) when repeating, texel 1 (green) when clamped.
  sp.uv = glm::vec2(1.25f, 0.5f);
  CHECK(near(shadeSurface(ctx, sp), glm::vec3(0.97f, 0.01f, 0.01f), 1e-5f));
  s.textures[0].sampler.wrapS = scene::Wrap::ClampToEdge;
  CHECK(near(shadeSurface(ctx, sp), glm::vec3(0.01f, 0.97f, 0.01f), 1e-5f));
  // Bilinear halfway between the texel centres (u = 0.5): an equal mix of the decoded texels.
  s.textures[0].sampler.magFilter = scene::Filter::Linear;
  sp.uv = glm::vec2(0.5f, 0.5f);
  CHECK(near(shadeSurface(ctx, sp), glm::vec3(0.49f, 0.49f, 0.01f), 1e-5f));
  // The texture is multiplied by the base colour factor.
  s.materials[0].baseColorFactor = glm::vec4(0.5f, 1.0f, 1.0f, 1.0f);
  CHECK(near(shadeSurface(ctx, sp), glm::vec3(0.25f, 0.49f, 0.01f), 1e-5f));
}

// shadeRegion shades headlit, untextured pixels four (SSE2) or eight (AVX2) at a time; each
// lane must compute exactly the per-pixel function (barycentrics, surface point, BRDF),
// whichever pixels share its batch and whichever kernel runs.
TEST_CASE("Shade: four- and eight-pixel lanes give the per-pixel colours bit for bit") {
  constexpr int kW = 61, kH = 37;  // odd sizes: rows end with partial batches
  CHECK((shadeLanes() == 4 || shadeLanes() == 8));
  if (shadeLanes() != 8) MESSAGE("this processor has no AVX2: the eight-lane kernel is not checked");
  const int variants = shadeLanes() == 8 ? 8 : 4;  // four scenes, through each kernel there is
  for (int variant = 0; variant < variants; ++variant) {
    const int lanes = variant < 4 ? 4 : 8;
    const bool vertexNormals = variant & 1, ortho = variant & 2;
    CAPTURE(variant);
    CAPTURE(lanes);
    scene::Scene s = test::emptyScene();
    scene::Material metal;
    metal.metallicFactor = 0.8f;
    metal.roughnessFactor = 0.02f;  // below the roughness clamp
    metal.baseColorFactor = glm::vec4(0.9f, 0.6f, 0.3f, 1.0f);
    metal.emissiveFactor = glm::vec3(0.25f, 0.0f, 0.5f);
    metal.doubleSided = true;
    s.materials.push_back(metal);
    // A fan of triangles at different depths and slopes, some seen from behind (double-sided).
    uint32_t seed = 12345u;
    auto rnd = [&seed] {
      seed = seed * 1664525u + 1013904223u;
      return float(seed >> 8) / float(1u << 24);
    };
    for (int t = 0; t < 24; ++t) {
      glm::vec3 c(rnd() * 8.0f - 4.0f, rnd() * 6.0f - 3.0f, -4.0f - rnd() * 6.0f);
      glm::vec3 a = c + glm::vec3(rnd() * 4.0f - 2.0f, rnd() * 4.0f - 2.0f, rnd() * 2.0f - 1.0f);
      glm::vec3 b = c + glm::vec3(rnd() * 4.0f - 2.0f, rnd() * 4.0f - 2.0f, rnd() * 2.0f - 1.0f);
      test::addTriangle(s, a, b, c, t % 2);
    }
    if (vertexNormals) {
      for (size_t v = 0; v < s.positions.size(); ++v)
        s.normals.push_back(glm::normalize(glm::vec3(rnd() - 0.5f, rnd() - 0.5f, 1.0f)));
    }
    const scene::Camera camera = ortho ? test::pixelOrthoCamera(8) : test::lookAtCamera({0, 0, 0}, {0, 0, -1});
    const FrameView view = makeFrameView(camera, kW, kH);
    std::vector<ScreenTriangle> tris;
    processTriangles(s, view, 0, uint32_t(s.triangles.size()), tris);
    RegionFramebuffer fb(Rect{0, 0, kW, kH});
    rasterizeTriangles(tris, fb);
    ShadingContext ctx = makeShadingContext(s, view);
    REQUIRE(ctx.usesHeadlight);
    ctx.lanes = lanes;
    ShadeCounters counters;
    shadeRegion(ctx, tris, fb, &counters);
    CHECK(counters.pixelsShaded == fb.coveredPixels());
    CHECK(fb.coveredPixels() > 200);
    int backFacing = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        if (!keyCovered(fb.key(x, y))) continue;
        const ScreenTriangle& tri = tris[fb.triangle(x, y)];
        backFacing += tri.backFacing;
        const glm::vec3 expected = shadeSurface(ctx, surfaceAt(s, tri, sceneBarycentrics(tri, x, y)));
        const glm::vec3 got = fb.colour(x, y);
        CAPTURE(x);
        CAPTURE(y);
        REQUIRE(std::memcmp(&got, &expected, sizeof got) == 0);
      }
    }
    CHECK(backFacing > 0);
  }
}

}  // namespace
}  // namespace pr::raster
