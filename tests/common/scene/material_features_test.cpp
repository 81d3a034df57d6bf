// Tests of the material features both families read through scene::resolveMaterial: the
// loader's KHR_materials_specular / clearcoat / sheen / variants, tangents from the file and
// generated (right-handed and mirrored UVs), normal-map perturbation, the alpha modes, and the
// sheen and clear-coat lobes' energy (common/scene/material_layers.h).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "common/scene/gltf_loader.h"
#include "common/scene/material_layers.h"
#include "common/scene/surface_material.h"
#include "common/scene/tangent_frame.h"
#include "common/util/error.h"
#include "common/util/log.h"
#include "tests/common/scene/gltf_writer.h"
#include "tests/test_support.h"

using namespace pr;

namespace {

constexpr float kPi = 3.14159265358979323846f;

// A unit quad in z = 0 facing +z with UVs (u along +x, v along -y as glTF's v runs down),
// mirrored: u along -x instead.
test::GltfWriter quad(bool mirroredUv, nlohmann::json material) {
  test::GltfWriter w;
  const float su = mirroredUv ? -1.0f : 1.0f;
  int pos = w.addFloats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3");
  int uv = w.addFloats({0, 1, su, 1, su, 0, 0, 0}, "VEC2");
  int idx = w.addIndices({0, 1, 2, 0, 2, 3});
  w.doc["materials"].push_back(material);
  int mesh = w.addMesh({{"POSITION", pos}, {"TEXCOORD_0", uv}}, idx, 4, 0);
  w.setRoots({w.addNode({{"mesh", mesh}})});
  return w;
}

scene::Scene load(const std::filesystem::path& p, const std::string& variant = "") {
  setQuiet(true);
  scene::Scene s = scene::loadGltf(p, scene::LoadOptions{variant});
  setQuiet(false);
  return s;
}

// A 1x1 texture (texel RGBA) as image 0 / texture 0 of w.
void addTexture(test::GltfWriter& w, std::vector<uint8_t> rgba) {
  w.doc["images"].push_back({{"uri", "data:image/png;base64," + test::base64(test::encodePng(1, 1, rgba))}});
  w.doc["textures"].push_back({{"source", 0}});
}

}  // namespace

TEST_CASE("MaterialFeatures: the loader reads KHR_materials_specular, clearcoat and sheen") {
  const auto dir = test::scratchDir("material_features_ext");
  nlohmann::json m = {{"extensions",
                       {{"KHR_materials_specular", {{"specularFactor", 0.25}, {"specularColorFactor", {1.0, 0.5, 0.0}}}},
                        {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.75}, {"clearcoatRoughnessFactor", 0.3}}},
                        {"KHR_materials_sheen", {{"sheenColorFactor", {0.2, 0.4, 0.6}}, {"sheenRoughnessFactor", 0.5}}}}}};
  test::GltfWriter w = quad(false, m);
  w.doc["extensionsUsed"] = {"KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen"};
  w.doc["extensionsRequired"] = {"KHR_materials_specular"};  // supported: no error
  const scene::Scene s = load(w.write(dir, "ext.gltf"));
  const scene::Material& mat = s.materials[0];
  CHECK(mat.specularFactor == 0.25f);
  CHECK(mat.specularColorFactor == glm::vec3(1.0f, 0.5f, 0.0f));
  CHECK(mat.clearcoatFactor == 0.75f);
  CHECK(mat.clearcoatRoughnessFactor == doctest::Approx(0.3f));
  CHECK(mat.sheenColorFactor.z == doctest::Approx(0.6f));
  CHECK(s.warnings.empty());
  const scene::SurfaceMaterial r = scene::resolveMaterial(s, 0, {});
  // F0 = ((1.5 - 1) / 2.5)^2 * specularColor * specularFactor, F90 = specularFactor.
  CHECK(r.dielectricF0().x == doctest::Approx(0.04f * 0.25f));
  CHECK(r.dielectricF0().y == doctest::Approx(0.02f * 0.25f));
  CHECK(r.dielectricF0().z == 0.0f);
  CHECK(r.dielectricF90() == 0.25f);
}

TEST_CASE("MaterialFeatures: KHR_materials_variants picks the mapped material, an unknown name is an input error") {
  const auto dir = test::scratchDir("material_features_variants");
  test::GltfWriter w = quad(false, {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}});
  w.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 1, 1}}}}});
  w.doc["extensionsUsed"] = {"KHR_materials_variants"};
  w.doc["extensions"]["KHR_materials_variants"]["variants"] = {{{"name", "red"}}, {{"name", "blue"}}};
  w.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"] = {
      {{"material", 1}, {"variants", {1}}}};
  const auto path = w.write(dir, "variants.gltf");
  CHECK(load(path).triangles[0].material == 0);
  CHECK(load(path, "red").triangles[0].material == 0);  // no mapping for it: the default
  const scene::Scene blue = load(path, "blue");
  CHECK(blue.triangles[0].material == 1);
  CHECK(blue.variant == "blue");
  CHECK(blue.variants == std::vector<std::string>{"red", "blue"});
  try {
    load(path, "green");
    FAIL("an unknown variant must be refused");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("red, blue") != std::string::npos);
  }
}

TEST_CASE("MaterialFeatures: an extension's texture index or variant material that is not a whole number is an input error") {
  const auto dir = test::scratchDir("material_features_whole_numbers");
  // A clearcoat texture whose index is a fraction.
  test::GltfWriter coat = quad(false, {{"extensions", {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}, {"clearcoatTexture", {{"index", 0.5}}}}}}}});
  coat.doc["extensionsUsed"] = {"KHR_materials_clearcoat"};
  addTexture(coat, {255, 255, 255, 255});
  CHECK_THROWS_WITH_AS(load(coat.write(dir, "coat_index.gltf")),
                       doctest::Contains("clearcoatTexture index is not a whole number within int's range"), InputError);
  // A variant mapped to material 1e30, and one mapped to a string.
  for (const nlohmann::json& material : {nlohmann::json(1e30), nlohmann::json("one")}) {
    test::GltfWriter w = quad(false, {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}});
    w.doc["extensionsUsed"] = {"KHR_materials_variants"};
    w.doc["extensions"]["KHR_materials_variants"]["variants"] = {{{"name", "red"}}};
    w.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"] = {
        {{"material", material}, {"variants", {0}}}};
    CAPTURE(material.dump());
    CHECK_THROWS_WITH_AS(load(w.write(dir, "variant_material.gltf"), "red"),
                         doctest::Contains("KHR_materials_variants material is not a whole number within int's range"),
                         InputError);
  }
}

TEST_CASE("MaterialFeatures: generated tangents follow +u, with w = -1 for mirrored UVs") {
  const auto dir = test::scratchDir("material_features_tangents");
  for (bool mirrored : {false, true}) {
    test::GltfWriter w = quad(mirrored, {{"normalTexture", {{"index", 0}}}});
    addTexture(w, {128, 128, 255, 255});
    const scene::Scene s = load(w.write(dir, mirrored ? "mirrored.gltf" : "plain.gltf"));
    REQUIRE(s.tangents.size() == s.positions.size());
    for (const glm::vec4& t : s.tangents) {
      CAPTURE(mirrored);
      CHECK(t.x == doctest::Approx(mirrored ? -1.0f : 1.0f));
      CHECK(std::fabs(t.y) < 1e-5f);
      // Bitangent w cross(n, t) must point along +v on the surface, which is -y here.
      const glm::vec3 b = t.w * glm::cross(glm::vec3(0, 0, 1), glm::vec3(t));
      CHECK(b.y == doctest::Approx(-1.0f));
    }
  }
}

TEST_CASE("MaterialFeatures: a normal map bends the normal towards its texel's direction, scaled") {
  const glm::vec3 n(0, 0, 1);
  const glm::vec4 t(1, 0, 0, 1);
  // The flat texel (0.5, 0.5, 1) keeps the normal.
  const glm::vec3 flat = scene::perturbNormal(n, t, glm::vec3(0.5f, 0.5f, 1.0f), 1.0f);
  CHECK(glm::length(flat - n) < 2e-2f);
  // +x in tangent space: the normal leans towards the tangent; scale 0 removes the lean.
  const glm::vec3 lean = scene::perturbNormal(n, t, glm::vec3(1.0f, 0.5f, 0.5f), 1.0f);
  CHECK(lean.x > 0.99f);
  CHECK(glm::length(scene::perturbNormal(n, t, glm::vec3(1.0f, 0.5f, 0.5f), 0.0f) - n) < 1e-6f);
  // Handedness -1 flips the bitangent: +y in tangent space leans the other way.
  CHECK(scene::perturbNormal(n, t, glm::vec3(0.5f, 1.0f, 0.5f), 1.0f).y > 0.99f);
  CHECK(scene::perturbNormal(n, glm::vec4(1, 0, 0, -1), glm::vec3(0.5f, 1.0f, 0.5f), 1.0f).y < -0.99f);
}

TEST_CASE("MaterialFeatures: resolveMaterial applies the normal map, vertex colour and emissive texture") {
  const auto dir = test::scratchDir("material_features_resolve");
  test::GltfWriter w = quad(false, {{"normalTexture", {{"index", 0}}}, {"emissiveTexture", {{"index", 0}}},
                                    {"emissiveFactor", {1, 1, 1}}});
  addTexture(w, {255, 128, 128, 255});  // tangent-space +x
  const scene::Scene s = load(w.write(dir, "resolve.gltf"));
  scene::SurfaceGeometry at;
  at.normal = glm::vec3(0, 0, 1);
  at.tangent = s.tangents[0];
  at.colour = glm::vec4(0.5f, 1.0f, 1.0f, 1.0f);
  const scene::SurfaceMaterial r = scene::resolveMaterial(s, 0, at);
  CHECK(r.normal.x > 0.99f);
  CHECK(r.baseColor.x == doctest::Approx(0.5f));  // COLOR_0 times the white default base
  CHECK(r.emission.x == doctest::Approx(1.0f));   // sRGB 255 decodes to 1
  CHECK(r.emission.y < 0.25f);                    // sRGB 128 decodes to about 0.22
  // Textures off: factors alone, and every slot skipped is counted.
  uint64_t skipped = 0;
  const scene::SurfaceMaterial f = scene::resolveMaterial(s, 0, at, false, &skipped);
  CHECK(f.normal == at.normal);
  CHECK(f.emission == glm::vec3(1.0f));
  CHECK(skipped == 2);
}

TEST_CASE("MaterialFeatures: alpha modes - OPAQUE always, MASK at the cutoff, BLEND with probability alpha") {
  scene::Material m;
  m.alphaMode = scene::AlphaMode::Opaque;
  CHECK(scene::alphaPasses(m, 0.0f, 0.99f));
  m.alphaMode = scene::AlphaMode::Mask;
  m.alphaCutoff = 0.4f;
  CHECK_FALSE(scene::alphaPasses(m, 0.39f, 0.0f));
  CHECK(scene::alphaPasses(m, 0.4f, 0.99f));
  m.alphaMode = scene::AlphaMode::Blend;
  int kept = 0;
  for (int i = 0; i < 1000; ++i) kept += scene::alphaPasses(m, 0.3f, (float(i) + 0.5f) / 1000.0f) ? 1 : 0;
  CHECK(kept == 300);
}

TEST_CASE("MaterialFeatures: the sheen albedo table matches direct integration, and stays below 1") {
  for (float roughness : {0.1f, 0.5f, 1.0f})
    for (float cosV : {0.2f, 0.6f, 1.0f}) {
      // Midpoint rule in (cos theta, phi), finer than the table's own.
      const float sinV = std::sqrt(1.0f - cosV * cosV);
      double sum = 0.0;
      const int nt = 400, np = 400;
      for (int i = 0; i < nt; ++i) {
        const float c = (float(i) + 0.5f) / nt, s = std::sqrt(1.0f - c * c);
        for (int j = 0; j < np; ++j) {
          const float phi = 2.0f * kPi * (float(j) + 0.5f) / np;
          const glm::vec3 h = glm::normalize(glm::vec3(sinV + s * std::cos(phi), s * std::sin(phi), cosV + c));
          sum += double(scene::sheenLobe(roughness, h.z, c, cosV) * c);
        }
      }
      const double direct = sum * (2.0 * kPi / np) / nt;
      CAPTURE(roughness);
      CAPTURE(cosV);
      CHECK(scene::sheenAlbedo(roughness, cosV) == doctest::Approx(direct).epsilon(0.03));
      CHECK(direct < 1.0);
    }
}
