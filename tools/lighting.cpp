// Lighting options (see lighting.h).
#include "tools/lighting.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "common/image/image_io.h"
#include "common/scene/gltf_loader.h"

namespace pr::cli {

void addLightingOptions(CLI::App& command, LightingOptions& o) {
  command.add_option("--env", o.env, "environment light: an equirectangular .exr or .hdr image, or 'sky' (a built-in studio sky)")
      ->check(CLI::Validator([](std::string& v) { return v == "sky" ? std::string() : CLI::ExistingFile(v); }, "FILE|sky"));
  command.add_option("--env-strength", o.strength, "environment radiance scale")->check(CLI::NonNegativeNumber)->capture_default_str();
  command.add_option("--env-rotate", o.rotateDegrees, "environment rotation about +y in degrees")
      ->check(CLI::Range(-360.0f, 360.0f))->capture_default_str();
  command.add_flag("--no-default-light", o.noDefault,
                   "a scene without lights gets no default light (otherwise: a uniform white environment)");
  command.add_option("--variant", o.variant, "KHR_materials_variants: the material variant to render (default: the default materials)");
}

scene::Scene loadScene(const std::string& path, const LightingOptions& o) {
  return scene::loadGltf(path, scene::LoadOptions{o.variant});
}

namespace {

// An emitter bright enough to light a scene: above 1 nit in some channel. glTF's emissive
// factor alone stops at 1 (a glowing sign or screen, as bright as a white surface under the
// default light); a lamp needs KHR_materials_emissive_strength to pass it.
bool isLamp(const scene::Material& m) {
  const glm::vec3 e = m.emission();
  return std::max(e.x, std::max(e.y, e.z)) > 1.0f;
}

}  // namespace

std::string applyLighting(scene::Scene& scene, const LightingOptions& o) {
  constexpr float kDegrees = 3.14159265358979323846f / 180.0f;
  if (o.env == "sky") {
    scene.environment = std::make_shared<const scene::Environment>(scene::Environment::sky(o.strength, o.rotateDegrees * kDegrees));
    return "lighting: the scene's lights and the built-in sky environment";
  }
  if (!o.env.empty()) {
    const image::Image image = image::readImage(o.env);
    scene.environment = std::make_shared<const scene::Environment>(scene::Environment::fromImage(
        image, o.strength, o.rotateDegrees * kDegrees, o.env));
    return "lighting: the scene's lights and the environment " + o.env;
  }
  if (!scene.lights.empty() || std::any_of(scene.areaLights.begin(), scene.areaLights.end(), [&](const scene::AreaLight& a) {
        return isLamp(scene.materials[scene.triangles[a.triangle].material]);
      }))
    return "lighting: the scene's own lights";
  if (o.noDefault) return "lighting: none (the scene has no lights; --no-default-light)";
  scene.environment = std::make_shared<const scene::Environment>(scene::Environment::uniform(
      glm::vec3(o.strength), "uniform white, the default: the scene has no lights"));
  return "lighting: the default, a uniform white environment (the scene has no lights)";
}

}  // namespace pr::cli
