// `parrender info SCENE [--json] [--camera SEL]`: loads a glTF scene into the render-ready
// layout and prints its statistics (common/scene/scene_stats.h) and the RenderPlan of the
// effect analysis (common/scene/effect_analysis.h) as an aligned table or JSON.
// The same loader and camera selection as `render`, so what it prints is what renderers get.
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/scene/gltf_loader.h"
#include "common/scene/scene_stats.h"
#include "tools/commands.h"
#include "tools/lighting.h"

namespace pr::cli {

namespace {

struct InfoOptions {
  std::string scene;
  bool json = false;
  std::string camera;
  LightingOptions lighting;  // as render applies them, so the plan is the render's
};

// Camera framing does not depend on an image here; a square image is assumed.
constexpr float kInfoAspect = 1.0f;

std::string vec3Text(glm::vec3 v) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "(%.6g, %.6g, %.6g)", v.x, v.y, v.z);
  return buffer;
}

std::string bytesText(size_t bytes) {
  char buffer[64];
  if (bytes >= (size_t(1) << 20)) {
    std::snprintf(buffer, sizeof buffer, "%.1f MiB (%zu bytes)", double(bytes) / double(1 << 20), bytes);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.1f KiB (%zu bytes)", double(bytes) / 1024.0, bytes);
  }
  return buffer;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "none" : out;
}

constexpr scene::MaterialKind kKinds[] = {scene::MaterialKind::Diffuse, scene::MaterialKind::Specular,
                                          scene::MaterialKind::Glass, scene::MaterialKind::Emissive,
                                          scene::MaterialKind::Anisotropic};

// "plan": {"direct": {"on": true, "forced": false, "reason": "..."}, ...} in plan order.
nlohmann::json planJson(const scene::RenderPlan& plan) {
  nlohmann::json out = nlohmann::json::object();
  for (scene::Effect e : scene::allEffects()) {
    const scene::EffectDecision& d = plan[e];
    out[std::string(scene::toString(e))] = {{"on", d.on}, {"forced", d.forced}, {"reason", d.reason}};
  }
  return out;
}

nlohmann::json toJson(const scene::SceneStats& s, const scene::Camera& camera, const scene::RenderPlan& plan) {
  using nlohmann::json;
  auto vec = [](glm::vec3 v) { return json::array({v.x, v.y, v.z}); };
  json materials = {{"total", s.materials}};
  for (scene::MaterialKind k : kKinds) materials[std::string(scene::toString(k))] = s.materialsByKind[size_t(k)];
  json bounds = s.bounds.empty() ? json(nullptr) : json{{"min", vec(s.bounds.min)}, {"max", vec(s.bounds.max)}};
  return json{
      {"file", s.file},
      {"triangles", s.triangles},
      {"vertices", s.vertices},
      {"objects", s.objects},
      {"materials", materials},
      {"lights",
       {{"point", s.pointLights}, {"spot", s.spotLights}, {"directional", s.directionalLights},
        {"area_triangles", s.areaLightTriangles}, {"emissive_area", s.emissiveArea}}},
      {"textures", {{"count", s.textures}, {"texels", s.texels}}},
      {"cameras", s.cameras},
      {"camera",
       {{"name", camera.name},
        {"projection", camera.projection == scene::Projection::Perspective ? "perspective" : "orthographic"},
        {"position", vec(camera.position())},
        {"automatic", camera.automatic}}},
      {"bounds", bounds},
      {"extensions_used", s.extensionsUsed},
      {"warnings", s.warnings},
      {"memory_bytes", s.memoryBytes},
      {"plan", planJson(plan)},
  };
}

std::string toTable(const scene::SceneStats& s, const scene::Camera& camera, const scene::RenderPlan& plan) {
  std::ostringstream out;
  auto row = [&](const char* key, const std::string& value) {
    char label[24];
    std::snprintf(label, sizeof label, "%-17s", key);
    out << label << value << "\n";
  };
  row("file", s.file);
  row("triangles", std::to_string(s.triangles));
  row("vertices", std::to_string(s.vertices));
  row("objects", std::to_string(s.objects));
  std::string kinds;
  for (scene::MaterialKind k : kKinds) {
    kinds += (kinds.empty() ? "" : ", ") + std::string(scene::toString(k)) + " " + std::to_string(s.materialsByKind[size_t(k)]);
  }
  row("materials", std::to_string(s.materials) + " used: " + kinds);
  row("lights", "point " + std::to_string(s.pointLights) + ", spot " + std::to_string(s.spotLights) + ", directional " +
                    std::to_string(s.directionalLights) + ", area_triangles " + std::to_string(s.areaLightTriangles));
  row("textures", std::to_string(s.textures) + " (" + std::to_string(s.texels) + " texels)");
  row("cameras", std::to_string(s.cameras));
  row("camera", "\"" + camera.name + "\" " +
                    (camera.projection == scene::Projection::Perspective ? "perspective" : "orthographic") + " at " +
                    vec3Text(camera.position()) + (camera.automatic ? " (automatic, frames the bounds)" : ""));
  row("bounds", s.bounds.empty() ? "empty" : vec3Text(s.bounds.min) + " .. " + vec3Text(s.bounds.max));
  row("extensions_used", join(s.extensionsUsed));
  row("warnings", s.warnings.empty() ? "none" : std::to_string(s.warnings.size()));
  for (const std::string& w : s.warnings) row("", w);
  row("memory_bytes", bytesText(s.memoryBytes));
  row("plan", "effects a render simulates (force with render --effects NAME=on|off)");
  for (scene::Effect e : scene::allEffects()) row("", plan.line(e));
  return out.str();
}

void runInfo(const InfoOptions& options) {
  scene::Scene scene = loadScene(options.scene, options.lighting);
  const std::string lighting = applyLighting(scene, options.lighting);
  scene::Camera camera = scene::selectCamera(scene, options.camera, kInfoAspect);
  scene::SceneStats stats = scene::computeStats(scene);
  const scene::RenderPlan plan = scene::analyzeEffects(scene, &camera);
  if (options.json) {
    nlohmann::json j = toJson(stats, camera, plan);
    j["lighting"] = lighting.substr(lighting.find(':') + 2);
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%s", toTable(stats, camera, plan).c_str());
    std::printf("%s\n", lighting.c_str());
  }
}

}  // namespace

void addInfoCommand(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Load a glTF 2.0 scene (.gltf or .glb) and print what the renderers will receive: triangles, "
      "vertices, objects (drawn mesh primitives), materials used by kind (diffuse, specular, glass, "
      "emissive, anisotropic), lights by kind (point, spot, directional, emissive area triangles), "
      "textures and texels, cameras and the selected one, world bounds, extensions used, warnings, "
      "the memory of the render-ready scene, and the render plan: each effect on or off with the reason. Bad input exits with status 2.");
  cmd->add_option("scene", options->scene, "glTF 2.0 file to inspect (.gltf with external or data: buffers, or .glb)")
      ->required();
  cmd->add_flag("--json", options->json, "print JSON (snake_case keys named like the table rows) instead of a table");
  cmd->add_option("--camera", options->camera,
                  "camera to report: an index or a name from the file, or \"auto\" for the framing camera "
                  "(default: the file's first camera, else auto)");
  addLightingOptions(*cmd, options->lighting);
  cmd->callback([options] {
    requireOneRank("info");
    runInfo(*options);
  });
}

}  // namespace pr::cli
