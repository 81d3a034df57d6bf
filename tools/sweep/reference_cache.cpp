// Reference images on disk (see reference_cache.h): DIR/<hash>.exr with DIR/<hash>.json, the
// hash being FNV-1a of the settings' canonical JSON text; the JSON is compared in full, so a
// hash collision cannot return the wrong image.
#include "tools/sweep/reference_cache.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "common/image/image_io.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/hash.h"

namespace pr::cli {

std::filesystem::path ReferenceCache::defaultDir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "parrender" / "references";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "parrender" / "references";
  return std::filesystem::path("parrender-references");
}

std::filesystem::path ReferenceCache::stem(const nlohmann::json& settings) const {
  const std::string text = settings.dump();
  Fnv1a h;
  h.bytes(text.data(), text.size());
  char name[32];
  std::snprintf(name, sizeof name, "ref-%016llx", static_cast<unsigned long long>(h.value()));
  return dir_ / name;
}

std::optional<image::Image> ReferenceCache::find(const nlohmann::json& settings) const {
  const std::filesystem::path base = stem(settings);
  std::ifstream in(base.string() + ".json");
  if (!in) return std::nullopt;
  const nlohmann::json stored = nlohmann::json::parse(in, nullptr, false);
  if (stored.is_discarded() || stored != settings || !std::filesystem::exists(base.string() + ".exr")) return std::nullopt;
  return image::readImage(base.string() + ".exr");
}

std::filesystem::path ReferenceCache::store(const nlohmann::json& settings, const image::Image& image) const {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw InputError("reference cache " + dir_.string() + ": cannot create the folder (" + ec.message() + ")");
  const std::filesystem::path base = stem(settings);
  const std::filesystem::path exr = base.string() + ".exr";
  image::writeImage(exr, image);
  writeFileAtomically(base.string() + ".json", settings.dump(2) + "\n", "reference cache file");
  return exr;
}

}  // namespace pr::cli
