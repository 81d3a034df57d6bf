// Choosing the camera a render uses: the file's first camera by default, another by index or
// name, or an automatic camera framing the scene bounds when the file has none.
#pragma once

#include <string>

#include "common/scene/camera.h"
#include "common/scene/scene.h"

namespace pr::scene {

// A perspective camera looking at the bounds' centre from +Z (glTF front), tilted slightly
// down, far enough back that the bounding sphere fits the vertical and horizontal fov.
Camera framingCamera(const Bounds& bounds, float aspect);

// selector: "" = the first camera (or framing when none); a number = index; otherwise a name.
// "auto" always gives the framing camera. An unknown index or name throws pr::InputError.
Camera selectCamera(const Scene& scene, const std::string& selector, float aspect);

}  // namespace pr::scene
