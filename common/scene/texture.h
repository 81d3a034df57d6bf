// Textures of the render-ready scene: an 8-bit RGBA image plus its glTF sampler.
// Texels stay encoded; sample() decodes sRGB for colour slots and filters with the sampler.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace pr::scene {

enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
enum class Filter : uint8_t { Nearest, Linear };

struct Sampler {
  Wrap wrapS = Wrap::Repeat;
  Wrap wrapT = Wrap::Repeat;
  Filter magFilter = Filter::Linear;
  Filter minFilter = Filter::Linear;  // mipmap modes map to their base filter
};

struct Texture {
  std::string name;  // image name or uri, for messages
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba8;  // width*height*4, row 0 = top (glTF UV v=0)
  Sampler sampler;

  // Filtered texel at uv (glTF convention); srgb decodes the RGB channels to linear.
  glm::vec4 sample(glm::vec2 uv, bool srgb) const;
  size_t memoryBytes() const { return rgba8.size(); }
};

}  // namespace pr::scene
