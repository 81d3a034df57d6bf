// Camera choice for a render (called once by the CLI before any PE starts): the file's first
// camera, one picked by --camera index or name, or a framing camera when the file has none.
#include "common/scene/camera_select.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "common/util/error.h"

namespace pr::scene {

Camera framingCamera(const Bounds& bounds, float aspect) {
  Camera camera;
  camera.name = "auto";
  camera.automatic = true;
  camera.yfov = 0.8f;  // about 46 degrees, a typical 50 mm-like view
  glm::vec3 center = bounds.empty() ? glm::vec3(0.0f) : bounds.center();
  float radius = bounds.empty() ? 1.0f : 0.5f * glm::length(bounds.extent());
  if (!(radius > 0.0f)) radius = 1.0f;  // a single point or a flat degenerate scene
  // The bounding sphere fits a cone of half-angle a at distance radius / sin(a); use the
  // narrower of the vertical and horizontal half fovs (tan(xfov/2) = aspect * tan(yfov/2)).
  float halfY = 0.5f * camera.yfov;
  float halfX = std::atan(std::max(aspect, 1e-3f) * std::tan(halfY));
  float distance = radius / std::sin(std::min(halfX, halfY));
  // Seen from +Z (glTF front), raised by kTilt so the top of the scene shows a little.
  constexpr float kTilt = 0.2f;  // radians, about 11 degrees down
  glm::vec3 back(0.0f, std::sin(kTilt), std::cos(kTilt));
  glm::vec3 eye = center + distance * back;
  glm::vec3 forward = -back;
  glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
  glm::vec3 up = glm::cross(right, forward);
  camera.cameraToWorld = glm::mat4(glm::vec4(right, 0.0f), glm::vec4(up, 0.0f), glm::vec4(back, 0.0f),
                                   glm::vec4(eye, 1.0f));
  // Near and far planes bracket the sphere with margin; near stays positive.
  camera.znear = std::max(0.5f * (distance - radius), 1e-3f * distance);
  camera.zfar = distance + 2.0f * radius;
  return camera;
}

Camera selectCamera(const Scene& scene, const std::string& selector, float aspect) {
  if (selector == "auto") return framingCamera(scene.bounds, aspect);
  if (selector.empty()) {
    if (scene.cameras.empty()) return framingCamera(scene.bounds, aspect);
    return scene.cameras.front();
  }
  size_t index = 0;
  auto [end, ec] = std::from_chars(selector.data(), selector.data() + selector.size(), index);
  if (ec == std::errc() && end == selector.data() + selector.size()) {
    if (index >= scene.cameras.size()) {
      throw InputError("camera " + selector + ": the scene has " + std::to_string(scene.cameras.size()) +
                       " camera(s); valid indices are 0.." +
                       (scene.cameras.empty() ? std::string("(none)") : std::to_string(scene.cameras.size() - 1)) +
                       " or \"auto\"");
    }
    return scene.cameras[index];
  }
  auto it = std::find_if(scene.cameras.begin(), scene.cameras.end(),
                         [&](const Camera& c) { return c.name == selector; });
  if (it == scene.cameras.end()) {
    std::string names;
    for (const Camera& c : scene.cameras) names += (names.empty() ? "" : ", ") + ("\"" + c.name + "\"");
    throw InputError("camera \"" + selector + "\": no camera of that name in " + scene.source.string() +
                     (names.empty() ? std::string(" (it has no cameras; use \"auto\")") : " (cameras: " + names + ")"));
  }
  return *it;
}

}  // namespace pr::scene
