// Environment: light arriving from infinitely far away in every direction - an equirectangular
// radiance image (EXR or Radiance HDR, read through OpenImageIO) or one uniform radiance - the
// light of `--env FILE` and the default light of a scene that has none. The ray tracers see it
// where a ray leaves the scene and sample it for direct light, by luminance (image) or
// uniformly over the sphere (uniform). Read-only after it is made; shared by every PE.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/image/image.h"

namespace pr::scene {

class Environment {
 public:
  // One radiance from every direction.
  static Environment uniform(const glm::vec3& radiance, std::string description);
  // An equirectangular image (u = 0.5 + atan2(d.x, -d.z) / 2 pi, v = acos(d.y) / pi: the image's
  // centre looks down -z, its top is +y), times strength, turned by `rotation` radians about +y.
  // Throws pr::InputError for an empty image or non-finite or negative radiance.
  static Environment fromImage(const image::Image& image, float strength, float rotation, std::string description);
  // A built-in studio sky (`--env sky`): a blue-white dome over a grey ground and a soft key
  // light high in front and to the left of a camera looking down -z, as glTF sample
  // screenshots are lit - so normal maps, metals and gloss show their shape, which a uniform
  // environment cannot. Times strength, turned by `rotation` radians about +y.
  static Environment sky(float strength, float rotation);

  bool isUniform() const { return width_ == 0; }
  const std::string& description() const { return description_; }
  // Radiance arriving along -dir, i.e. seen looking in the unit direction dir.
  glm::vec3 radiance(const glm::vec3& dir) const;
  // A direction with probability density pdf (solid angle) for (u, v) in [0, 1)^2: by pixel
  // luminance times the pixel's solid angle (image), uniform over the sphere (uniform).
  glm::vec3 sample(float u, float v, float& pdf) const;
  // The density with which sample() produces dir.
  float pdf(const glm::vec3& dir) const;
  // Mean luminance over the sphere (the environment's share when lights are picked by power).
  float meanLuminance() const { return meanLuminance_; }
  std::size_t bytes() const { return pixels_.size() * sizeof(glm::vec3) + (rowCdf_.size() + columnCdf_.size()) * sizeof(float); }

 private:
  glm::vec2 uvOf(const glm::vec3& dir) const;
  glm::vec3 dirOf(float u, float v) const;

  std::string description_;
  glm::vec3 uniform_{0.0f};
  int width_ = 0, height_ = 0;
  float rotation_ = 0.0f;
  std::vector<glm::vec3> pixels_;  // radiance, strength applied
  std::vector<float> rowCdf_;      // height + 1 entries, 0 .. 1
  std::vector<float> columnCdf_;   // per row, width + 1 entries, 0 .. 1
  std::vector<float> rowWeight_;   // per row: its share of the total
  float meanLuminance_ = 0.0f;
};

}  // namespace pr::scene
