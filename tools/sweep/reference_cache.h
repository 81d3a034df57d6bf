// The reference images of `parrender sweep`: long path-traced renders kept on disk, each beside
// the settings that made it (scene file and its size and time, camera, image size, spp, depth,
// seed, effects), and reused only when a request's settings match exactly. A reference costs
// minutes; a sweep over ten settings should not pay for it ten times, nor twice a day.
#pragma once

#include <filesystem>
#include <optional>

#include <nlohmann/json.hpp>

#include "common/image/image.h"

namespace pr::cli {

class ReferenceCache {
 public:
  // dir is created on the first store.
  explicit ReferenceCache(std::filesystem::path dir) : dir_(std::move(dir)) {}
  // The default folder: $XDG_CACHE_HOME/parrender/references, else ~/.cache/parrender/references.
  static std::filesystem::path defaultDir();

  const std::filesystem::path& dir() const { return dir_; }
  // The cached image made with exactly these settings, if any.
  std::optional<image::Image> find(const nlohmann::json& settings) const;
  // Stores the image (32-bit float EXR) and its settings; returns the image's path.
  std::filesystem::path store(const nlohmann::json& settings, const image::Image& image) const;

 private:
  std::filesystem::path stem(const nlohmann::json& settings) const;
  std::filesystem::path dir_;
};

}  // namespace pr::cli
