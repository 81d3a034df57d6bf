// See scene_hash.h.
#include "common/scene/scene_hash.h"

#include <span>
#include <string_view>

namespace pr::scene {
namespace {

class Fnv {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 1099511628211ull;
  }
  template <class T>
  void all(std::span<const T> items) {
    const std::uint64_t n = items.size();
    bytes(&n, sizeof n);
    bytes(items.data(), items.size_bytes());
  }
  void text(std::string_view s) { all(std::span<const char>(s.data(), s.size())); }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 1469598103934665603ull;
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
