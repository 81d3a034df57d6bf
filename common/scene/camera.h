// Cameras of the render-ready scene (glTF perspective/orthographic, placed in world space)
// and the automatic camera that frames the scene bounds when a file has none.
#pragma once

#include <string>

#include <glm/glm.hpp>

namespace pr::scene {

enum class Projection { Perspective, Orthographic };

struct Camera {
  std::string name;
  Projection projection = Projection::Perspective;
  glm::mat4 cameraToWorld{1.0f};  // camera looks down -Z, +Y up (glTF)
  float yfov = 0.8f;              // radians (perspective)
  float xmag = 1.0f, ymag = 1.0f; // half extents (orthographic)
  float znear = 0.01f;
  float zfar = 0.0f;              // 0 = infinite (perspective)
  float fileAspectRatio = 0.0f;   // the file's aspectRatio; 0 when absent (unused: image aspect wins)
  bool automatic = false;         // true for the framing camera made when the file has none

  glm::vec3 position() const { return glm::vec3(cameraToWorld[3]); }
  glm::mat4 view() const { return glm::inverse(cameraToWorld); }
  // Projection for an image of the given aspect (width / height); the image aspect wins over
  // the file's aspectRatio so pixels stay square. Orthographic keeps ymag and widens x.
  glm::mat4 projectionMatrix(float aspect) const;
};

}  // namespace pr::scene
