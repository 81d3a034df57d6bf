// Tests of texture sampling (common/scene/texture.cpp): wrap modes, nearest and bilinear
// filtering, sRGB decoding before filtering, and KHR_texture_transform UV mapping.
#include <doctest/doctest.h>

#include <cmath>

#include "common/scene/gltf_loader.h"
#include "common/scene/material.h"
#include "common/scene/texture.h"
#include "common/util/log.h"
#include "test_support.h"
#include "tests/common/scene/gltf_writer.h"

namespace {

using pr::scene::Filter;
using pr::scene::Texture;
using pr::scene::Wrap;

// 2x1 texture: left texel black, right texel white (alpha 255 for both).
Texture blackWhite(Wrap wrap, Filter filter) {
  Texture t;
  t.width = 2;
  t.height = 1;
  t.rgba8 = {0, 0, 0, 255, 255, 255, 255, 255};
  t.sampler.wrapS = t.sampler.wrapT = wrap;
  t.sampler.magFilter = t.sampler.minFilter = filter;
  return t;
}

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

}  // namespace

TEST_CASE("Texture: nearest sampling picks the texel containing uv") {
  Texture t = blackWhite(Wrap::Repeat, Filter::Nearest);
  CHECK(t.sample({0.25f, 0.5f}, false).x == 0.0f);
  CHECK(t.sample({0.75f, 0.5f}, false).x == 1.0f);
  CHECK(t.sample({0.75f, 0.5f}, false).w == 1.0f);
}

TEST_CASE("Texture: wrap modes map uv outside [0,1]") {
  // u = 1.25 is texel 2.5 -> texel 2: repeat -> 0 (black), clamp -> 1 (white),
  // mirrored (period 4: 0 1 1 0) -> 1 (white). u = -0.25 is texel -1: repeat -> 1 (white),
  // clamp -> 0 (black), mirrored -> 0 (black).
  CHECK(blackWhite(Wrap::Repeat, Filter::Nearest).sample({1.25f, 0.5f}, false).x == 0.0f);
  CHECK(blackWhite(Wrap::ClampToEdge, Filter::Nearest).sample({1.25f, 0.5f}, false).x == 1.0f);
  CHECK(blackWhite(Wrap::MirroredRepeat, Filter::Nearest).sample({1.25f, 0.5f}, false).x == 1.0f);
  CHECK(blackWhite(Wrap::Repeat, Filter::Nearest).sample({-0.25f, 0.5f}, false).x == 1.0f);
  CHECK(blackWhite(Wrap::ClampToEdge, Filter::Nearest).sample({-0.25f, 0.5f}, false).x == 0.0f);
  CHECK(blackWhite(Wrap::MirroredRepeat, Filter::Nearest).sample({-0.25f, 0.5f}, false).x == 0.0f);
  // u = 1.75 (texel 3): mirrored reads texel 0 (black), repeat texel 1 (white).
  CHECK(blackWhite(Wrap::MirroredRepeat, Filter::Nearest).sample({1.75f, 0.5f}, false).x == 0.0f);
  CHECK(blackWhite(Wrap::Repeat, Filter::Nearest).sample({1.75f, 0.5f}, false).x == 1.0f);
}

TEST_CASE("Texture: bilinear filtering blends texel centres, with wrap at the edges") {
  // Texel centres at u = 0.25 (black) and 0.75 (white): u = 0.5 is halfway.
  Texture clamp = blackWhite(Wrap::ClampToEdge, Filter::Linear);
  CHECK(clamp.sample({0.5f, 0.5f}, false).x == doctest::Approx(0.5f));
  CHECK(clamp.sample({0.375f, 0.5f}, false).x == doctest::Approx(0.25f));
  // At u = 0 clamp holds black; repeat blends with the wrapped-around white texel equally.
  CHECK(clamp.sample({0.0f, 0.5f}, false).x == doctest::Approx(0.0f));
  CHECK(blackWhite(Wrap::Repeat, Filter::Linear).sample({0.0f, 0.5f}, false).x == doctest::Approx(0.5f));
}

TEST_CASE("Texture: sRGB texels are decoded to linear before filtering") {
  Texture t;
  t.width = 1;
  t.height = 1;
  t.rgba8 = {128, 64, 255, 128};
  t.sampler.magFilter = Filter::Nearest;
  glm::vec4 lin = t.sample({0.5f, 0.5f}, true);
  CHECK(lin.x == doctest::Approx(srgbToLinear(128.0f / 255.0f)));  // about 0.216, not 0.502
  CHECK(lin.y == doctest::Approx(srgbToLinear(64.0f / 255.0f)));
  CHECK(lin.z == doctest::Approx(1.0f));
  CHECK(lin.w == doctest::Approx(128.0f / 255.0f));  // alpha is always linear
  CHECK(t.sample({0.5f, 0.5f}, false).x == doctest::Approx(128.0f / 255.0f));
  // Filtering happens after decoding: halfway between black and white is 0.5 linear, where
  // filtering the codes first would decode 127.5 to about 0.21.
  Texture bw = blackWhite(Wrap::ClampToEdge, Filter::Linear);
  CHECK(bw.sample({0.5f, 0.5f}, true).x == doctest::Approx(0.5f));
}

TEST_CASE("Texture: KHR_texture_transform maps UVs as offset * rotation * scale") {
  pr::scene::TextureRef ref;
  // Offset (0, 1), rotation 90 deg, scale 0.5: the extension's example that reads only the
  // lower-left quadrant: (u, v) -> (0.5 v, 1 - 0.5 u).
  float c = 0.0f, s = 1.0f;
  ref.uvTransform = glm::mat3(1, 0, 0, 0, 1, 0, 0, 1, 1) * glm::mat3(c, -s, 0, s, c, 0, 0, 0, 1) *
                    glm::mat3(0.5f, 0, 0, 0, 0.5f, 0, 0, 0, 1);
  glm::vec2 uv = ref.transformUv({1.0f, 1.0f});
  CHECK(uv.x == doctest::Approx(0.5f));
  CHECK(uv.y == doctest::Approx(0.5f));
  uv = ref.transformUv({0.0f, 0.0f});
  CHECK(uv.y == doctest::Approx(1.0f));
}

TEST_CASE("Texture: TextureTransformTest materials carry their transforms and clamp sampler") {
  if (!pr::test::haveSharedScenes()) return;
  pr::setQuiet(true);
  auto s = pr::scene::loadGltf(pr::test::sharedScenes() / "TextureTransformTest/glTF/TextureTransformTest.gltf");
  pr::setQuiet(false);
  auto find = [&](const std::string& name) -> const pr::scene::Material& {
    for (const auto& m : s.materials)
      if (m.name == name) return m;
    FAIL("no material " << name);
    return s.materials.front();
  };
  // "Offset U": offset (0.5, 0) moves (0, 0) to (0.5, 0).
  glm::vec2 uv = find("Offset U").baseColorTexture.transformUv({0.0f, 0.0f});
  CHECK(uv.x == doctest::Approx(0.5f));
  CHECK(uv.y == doctest::Approx(0.0f));
  // "Scale": (1, 1) -> (1.5, 1.5).
  uv = find("Scale").baseColorTexture.transformUv({1.0f, 1.0f});
  CHECK(uv.x == doctest::Approx(1.5f));
  // "Rotation" 22.5 deg: (1, 0) -> (cos, -sin).
  uv = find("Rotation").baseColorTexture.transformUv({1.0f, 0.0f});
  CHECK(uv.x == doctest::Approx(std::cos(0.39269908f)));
  CHECK(uv.y == doctest::Approx(-std::sin(0.39269908f)));
  const auto& tex = s.textures[size_t(find("Scale").baseColorTexture.texture)];
  CHECK((tex.sampler.wrapS == Wrap::ClampToEdge));
  CHECK(tex.width > 0);
  CHECK(tex.rgba8.size() == size_t(tex.width) * size_t(tex.height) * 4);
}

TEST_CASE("Texture: a PNG in a bufferView loads as 8-bit RGBA with its sampler's modes") {
  auto dir = pr::test::scratchDir("texture_buffer_view");
  pr::test::GltfWriter w = pr::test::oneTriangle();
  // 2x2: red, green / blue, white with alpha 128.
  std::vector<uint8_t> texels = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  auto png = pr::test::encodePng(2, 2, texels);
  int view = w.addView(png.data(), png.size());
  w.doc["images"] = {{{"bufferView", view}, {"mimeType", "image/png"}}};
  w.doc["samplers"] = {{{"magFilter", 9728}, {"minFilter", 9986}, {"wrapS", 33648}, {"wrapT", 33071}}};
  w.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  w.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  w.doc["meshes"][0]["primitives"][0]["material"] = 0;
  pr::setQuiet(true);
  auto s = pr::scene::loadGltf(w.write(dir, "buffer_view_png.gltf"));
  pr::setQuiet(false);
  REQUIRE(s.textures.size() == 1);
  const Texture& t = s.textures[0];
  CHECK(t.rgba8 == texels);
  CHECK((t.sampler.wrapS == Wrap::MirroredRepeat));
  CHECK((t.sampler.wrapT == Wrap::ClampToEdge));
  CHECK((t.sampler.magFilter == Filter::Nearest));
  CHECK((t.sampler.minFilter == Filter::Nearest));  // NEAREST_MIPMAP_LINEAR keeps its base filter
  CHECK(s.materials[0].baseColorTexture.texture == 0);
  // v = 0.75 is the bottom row: blue at u = 0.25; the white texel's alpha stays linear.
  CHECK(t.sample({0.25f, 0.75f}, true) == glm::vec4(0, 0, 1, 1));
  CHECK(t.sample({0.75f, 0.75f}, true).w == doctest::Approx(128.0f / 255.0f));
}
