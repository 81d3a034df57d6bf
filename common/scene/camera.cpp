// Projection matrices of scene cameras (OpenGL clip conventions, as glTF 2.0 specifies them,
// section 3.10.3): the rasterizers transform by projectionMatrix(aspect) * view().
#include "common/scene/camera.h"

#include <glm/gtc/matrix_transform.hpp>

namespace pr::scene {

glm::mat4 Camera::projectionMatrix(float aspect) const {
  if (projection == Projection::Orthographic) {
    // The image aspect wins: keep the vertical half extent, widen or narrow x to match.
    float halfHeight = ymag;
    float halfWidth = ymag * aspect;
    float farPlane = zfar > znear ? zfar : znear + 1.0f;
    return glm::ortho(-halfWidth, halfWidth, -halfHeight, halfHeight, znear, farPlane);
  }
  if (zfar <= 0.0f) return glm::infinitePerspective(yfov, aspect, znear);
  return glm::perspective(yfov, aspect, znear, zfar);
}

}  // namespace pr::scene
