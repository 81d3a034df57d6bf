// See scene_hash.h.
#include "common/scene/scene_hash.h"

#include <span>
#include <string_view>

#include "common/util/hash.h"

namespace pr::scene {
namespace {

// FNV-1a over sequences, each preceded by its length.
class Fnv : public Fnv1a {
 public:
  template <class T>
  void all(std::span<const T> items) {
    const std::uint64_t n = items.size();
    bytes(&n, sizeof n);
    bytes(items.data(), items.size_bytes());
  }
  void text(std::string_view s) { all(std::span<const char>(s.data(), s.size())); }
};

}  // namespace

std::uint64_t contentHash(const Scene& scene) {
  Fnv h;
  h.all(std::span<const glm::vec3>(scene.positions));
  h.all(std::span<const glm::vec3>(scene.normals));
  h.all(std::span<const glm::vec2>(scene.uvs));
  h.all(std::span<const glm::vec4>(scene.colors));
  h.all(std::span<const glm::vec4>(scene.tangents));
  h.all(std::span<const Triangle>(scene.triangles));
  for (const Texture& t : scene.textures) {
    h.bytes(&t.width, sizeof t.width);
    h.bytes(&t.height, sizeof t.height);
    h.all(std::span<const uint8_t>(t.rgba8));
  }
  for (const Material& m : scene.materials) h.text(m.name);
  return h.value();
}

}  // namespace pr::scene
