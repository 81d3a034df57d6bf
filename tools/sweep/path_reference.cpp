// The path-traced reference (see path_reference.h).
#include "tools/sweep/path_reference.h"

#include <cstdio>
#include <optional>
#include <system_error>

#include <nlohmann/json.hpp>

#include "common/parallel/process_group.h"
#include "tools/sweep/reference_cache.h"

namespace pr::cli {

namespace {
// The reference's own random stream: apart from every render of a series, so that the path
// tracer's error at spp N is not shrunk by sharing the reference's first N samples.
constexpr std::uint64_t kReferenceSeedOffset = 0x5eed0f4e4e4e4e4eull;
}  // namespace

Reference pathReference(const ReferenceSettings& s, const RenderInput& input) {
  std::error_code ec;
  const std::filesystem::path scenePath = std::filesystem::canonical(s.sceneFile, ec);
  const nlohmann::json key = {{"kind", "path-traced reference"}, {"scene", scenePath.string()},
                              {"sceneBytes", std::filesystem::file_size(s.sceneFile)},
                              {"sceneTime", std::filesystem::last_write_time(s.sceneFile).time_since_epoch().count()},
                              {"camera", s.camera}, {"width", input.width}, {"height", input.height}, {"spp", s.spp},
                              {"maxDepth", s.maxDepth}, {"seed", s.seed ^ kReferenceSeedOffset}, {"effects", s.effects},
                              {"env", s.lighting.env}, {"envStrength", s.lighting.strength},
                              {"envRotate", s.lighting.rotateDegrees}, {"noDefaultLight", s.lighting.noDefault},
                              {"variant", s.lighting.variant}};
  const ReferenceCache cache(s.dir.empty() ? ReferenceCache::defaultDir() : s.dir);
  Reference out;
  // Whether the cache holds it is rank 0's to know (it alone reads files): one byte to the others.
  const par::Bytes cached = par::ProcessGroup::get().onRank0Alone("rank 0's look in the reference cache", [&] {
    if (!s.noCache)
      if (std::optional<image::Image> image = cache.find(key)) {
        out.image = std::move(*image);
        out.cached = true;
        std::fprintf(stderr, "reference: cached (path, spp %d) in %s\n", s.spp, cache.dir().string().c_str());
      }
    return par::Bytes{std::byte(out.cached)};
  });
  if (cached.at(0) != std::byte(0)) {
    out.cached = true;
    return out;
  }
  const bool holds = holdsResults();
  if (holds) std::fprintf(stderr, "reference: rendering (path, spp %d, depth %d) ...\n", s.spp, s.maxDepth);
  RenderSettings settings;
  settings.ray.integrator = "path";
  settings.ray.spp = s.spp;
  settings.ray.maxDepth = s.maxDepth;
  settings.ray.seed = s.seed ^ kReferenceSeedOffset;
  TimedRender t = timedRender(findRenderMethod(s.method), input, settings, s.where, s.schedule);
  out.cpuSeconds = t.cpuSeconds;
  out.image = std::move(t.outcome.image);
  if (!holds) return out;  // rank 0 holds the image
  if (!s.noCache) out.file = cache.store(key, out.image);
  std::fprintf(stderr, "reference: %.1f CPU s%s%s\n", out.cpuSeconds, out.file.empty() ? "" : ", stored as ",
               out.file.string().c_str());
  return out;
}

}  // namespace pr::cli
