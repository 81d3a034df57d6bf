// The environment light (see environment.h): equirectangular lookup and the two-level
// (marginal rows, conditional columns) luminance distribution for importance sampling.
#include "common/scene/environment.h"

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

namespace pr::scene {

namespace {
constexpr float kPi = 3.14159265358979323846f;
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;
float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// Index of the interval of cdf (size n + 1, cdf[0] = 0, cdf[n] = 1) holding u, and u's place in it.
int pick(const float* cdf, int n, float u, float& within) {
  const float* it = std::upper_bound(cdf, cdf + n + 1, u);
  const int i = std::clamp(int(it - cdf) - 1, 0, n - 1);
  const float width = cdf[i + 1] - cdf[i];
  within = width > 0.0f ? std::clamp((u - cdf[i]) / width, 0.0f, kOneMinusEpsilon) : 0.5f;
  return i;
}
}  // namespace

Environment Environment::uniform(const glm::vec3& radiance, std::string description) {
  Environment e;
  e.uniform_ = glm::max(radiance, glm::vec3(0.0f));
  e.description_ = std::move(description);
  e.meanLuminance_ = luminance(e.uniform_);
  return e;
}

Environment Environment::sky(float strength, float rotation) {
  constexpr int kW = 512, kH = 256;
  image::Image img(kW, kH);
  const glm::vec3 key = glm::normalize(glm::vec3(-0.5f, 0.7f, 0.5f));
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      // The pixel's direction, as fromImage maps it (unrotated).
      const float phi = 2.0f * kPi * ((float(x) + 0.5f) / kW - 0.5f), theta = kPi * (float(y) + 0.5f) / kH;
      const glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      const float up = d.y;
      glm::vec3 l = up >= 0.0f ? glm::mix(glm::vec3(1.0f), glm::vec3(0.55f, 0.7f, 1.0f), std::sqrt(up))
                               : glm::mix(glm::vec3(0.45f), glm::vec3(0.25f), std::min(1.0f, -4.0f * up));
      // The key light: a lobe about 10 degrees wide, carrying about as much light as the dome.
      l += glm::vec3(60.0f, 57.0f, 52.0f) * std::exp((glm::dot(d, key) - 1.0f) / 0.015f);
      img.at(x, y) = l;
    }
  return fromImage(img, strength, rotation, "sky (built-in studio environment)");
}

Environment Environment::fromImage(const image::Image& image, float strength, float rotation, std::string description) {
  if (image.empty()) throw InputError("environment " + description + ": the image has no pixels");
  if (!(strength >= 0.0f) || !std::isfinite(strength)) throw InputError("environment strength must be a finite number >= 0");
  Environment e;
  e.description_ = std::move(description);
  e.width_ = image.width;
  e.height_ = image.height;
  e.rotation_ = std::isfinite(rotation) ? rotation : 0.0f;
  e.pixels_.resize(image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const glm::vec3 p = image.pixels[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || p.x < 0.0f || p.y < 0.0f || p.z < 0.0f)
      throw InputError("environment " + e.description_ + ": pixel " + std::to_string(i) + " is negative or not finite");
    e.pixels_[i] = p * strength;
  }
  // Weights: luminance x the pixel's solid angle (sin theta of its row centre); a floor keeps
  // every direction sampleable, so the estimator stays unbiased where the image is black.
  const int w = e.width_, h = e.height_;
  std::vector<double> rows(static_cast<std::size_t>(h), 0.0);
  e.columnCdf_.assign(std::size_t(h) * std::size_t(w + 1), 0.0f);
  double total = 0.0, lumSum = 0.0, solid = 0.0;
  for (int y = 0; y < h; ++y) {
    const double sinTheta = std::sin(kPi * (double(y) + 0.5) / double(h));
    double running = 0.0;
    std::vector<double> cells(static_cast<std::size_t>(w));
    for (int x = 0; x < w; ++x) {
      const double lum = luminance(e.pixels_[std::size_t(y) * std::size_t(w) + std::size_t(x)]);
      lumSum += lum * sinTheta;
      solid += sinTheta;
      cells[std::size_t(x)] = (lum + 1e-6) * sinTheta;
      running += cells[std::size_t(x)];
    }
    float* cdf = &e.columnCdf_[std::size_t(y) * std::size_t(w + 1)];
    double acc = 0.0;
    for (int x = 0; x < w; ++x) {
      acc += cells[std::size_t(x)];
      cdf[x + 1] = x + 1 == w ? 1.0f : float(acc / running);
    }
    rows[std::size_t(y)] = running;
    total += running;
  }
  e.rowCdf_.assign(std::size_t(h + 1), 0.0f);
  e.rowWeight_.resize(std::size_t(h));
  double acc = 0.0;
  for (int y = 0; y < h; ++y) {
    acc += rows[std::size_t(y)];
    e.rowCdf_[std::size_t(y + 1)] = y + 1 == h ? 1.0f : float(acc / total);
    e.rowWeight_[std::size_t(y)] = float(rows[std::size_t(y)] / total);
  }
  e.meanLuminance_ = solid > 0.0 ? float(lumSum / solid) : 0.0f;
  return e;
}

glm::vec2 Environment::uvOf(const glm::vec3& d) const {
  float u = 0.5f + (std::atan2(d.x, -d.z) - rotation_) / (2.0f * kPi);
  u -= std::floor(u);
  const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi;
  return {std::min(u, kOneMinusEpsilon), std::min(v, kOneMinusEpsilon)};
}

glm::vec3 Environment::dirOf(float u, float v) const {
  const float phi = 2.0f * kPi * (u - 0.5f) + rotation_;
  const float theta = kPi * v;
  const float s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

glm::vec3 Environment::radiance(const glm::vec3& dir) const {
  if (isUniform()) return uniform_;
  const glm::vec2 uv = uvOf(dir);
  const int x = std::min(width_ - 1, int(uv.x * float(width_)));
  const int y = std::min(height_ - 1, int(uv.y * float(height_)));
  return pixels_[std::size_t(y) * std::size_t(width_) + std::size_t(x)];
}

glm::vec3 Environment::sample(float u, float v, float& pdf) const {
  if (isUniform()) {
    const float z = 1.0f - 2.0f * u;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * v;
    pdf = 1.0f / (4.0f * kPi);
    return {r * std::cos(phi), z, r * std::sin(phi)};
  }
  float fy, fx;
  const int y = pick(rowCdf_.data(), height_, u, fy);
  const int x = pick(&columnCdf_[std::size_t(y) * std::size_t(width_ + 1)], width_, v, fx);
  const glm::vec3 dir = dirOf((float(x) + fx) / float(width_), (float(y) + fy) / float(height_));
  pdf = this->pdf(dir);
  return dir;
}

float Environment::pdf(const glm::vec3& dir) const {
  if (isUniform()) return 1.0f / (4.0f * kPi);
  const glm::vec2 uv = uvOf(dir);
  const int x = std::min(width_ - 1, int(uv.x * float(width_)));
  const int y = std::min(height_ - 1, int(uv.y * float(height_)));
  const float* cdf = &columnCdf_[std::size_t(y) * std::size_t(width_ + 1)];
  // A point uniform in the pixel's (u, v) rectangle has solid-angle density
  // p_pixel / ((2 pi / W)(pi / H) sin(theta)), sin(theta) of the direction itself.
  const float pPixel = rowWeight_[std::size_t(y)] * (cdf[x + 1] - cdf[x]);
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - dir.y * dir.y));
  const float solid = (2.0f * kPi / float(width_)) * (kPi / float(height_)) * std::max(sinTheta, 1e-6f);
  return pPixel / solid;
}

}  // namespace pr::scene
