// Size of the render-ready scene: what a world-model PE holds, and what a broadcast of the
// scene ADI costs (counted once per receiving PE by the Channel).
#include "common/scene/scene.h"

namespace pr::scene {

namespace {
template <class T>
size_t bytesOf(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}
}  // namespace

size_t Scene::geometryBytes() const {
  return bytesOf(positions) + bytesOf(normals) + bytesOf(uvs) + bytesOf(colors) + bytesOf(tangents) +
         bytesOf(triangles) + bytesOf(objects);
}

size_t Scene::memoryBytes() const {
  size_t bytes = geometryBytes() + bytesOf(materials) + bytesOf(textures) + bytesOf(lights) + bytesOf(areaLights) +
                 bytesOf(cameras);
  for (const Texture& t : textures) bytes += t.memoryBytes();
  return bytes;
}

}  // namespace pr::scene
