// Tests of material classification (common/scene/material.cpp), on hand-set materials and on
// the shared KHR extension test models.
#include <doctest/doctest.h>

#include "common/scene/gltf_loader.h"
#include "common/scene/material.h"
#include "common/util/log.h"
#include "test_support.h"

using pr::scene::Material;
using pr::scene::MaterialKind;

TEST_CASE("Material: kind follows the priority emissive > glass > anisotropic > specular > diffuse") {
  Material m;  // glTF default: metallic 1, roughness 1 -> a rough metal, diffuse-like
  CHECK((m.kind() == MaterialKind::Diffuse));
  m.roughnessFactor = 0.1f;
  CHECK((m.kind() == MaterialKind::Specular));
  m.anisotropyStrength = 0.5f;
  CHECK((m.kind() == MaterialKind::Anisotropic));
  m.transmissionFactor = 1.0f;
  CHECK((m.kind() == MaterialKind::Glass));
  m.emissiveFactor = glm::vec3(0.0f, 0.2f, 0.0f);
  CHECK((m.kind() == MaterialKind::Emissive));
  m.emissiveStrength = 0.0f;  // strength 0 switches emission off
  CHECK((m.kind() == MaterialKind::Glass));
  CHECK(pr::scene::toString(MaterialKind::Anisotropic) == "anisotropic");
}

TEST_CASE("Material: KHR extension values are read from the shared models") {
  if (!pr::test::haveSharedScenes()) return;
  pr::setQuiet(true);
  auto trans = pr::scene::loadGltf(pr::test::sharedScenes() / "TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb");
  auto atten = pr::scene::loadGltf(pr::test::sharedScenes() / "AttenuationTest/glTF-Binary/AttenuationTest.glb");
  auto aniso = pr::scene::loadGltf(pr::test::sharedScenes() / "AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb");
  pr::setQuiet(false);
  // README: ior rows 1.0 / 1.33 / 1.5 / 1.76 / 2.42, thicknessFactor 0.005.
  float maxIor = 0.0f, minIor = 10.0f;
  bool thin = false, glass = false;
  for (const auto& m : trans.materials) {
    maxIor = std::max(maxIor, m.ior);
    minIor = std::min(minIor, m.ior);
    thin = thin || m.thicknessFactor == doctest::Approx(0.005f);
    glass = glass || m.kind() == MaterialKind::Glass;
  }
  CHECK(maxIor == doctest::Approx(2.42f));
  CHECK(minIor == doctest::Approx(1.0f));
  CHECK(thin);
  CHECK(glass);
  bool finiteDistance = false;
  for (const auto& m : atten.materials) finiteDistance = finiteDistance || std::isfinite(m.attenuationDistance);
  CHECK(finiteDistance);
  size_t anisotropic = 0;
  for (const auto& m : aniso.materials) anisotropic += m.kind() == MaterialKind::Anisotropic;
  CHECK(anisotropic > 10);
}
