// Photon tracing as a pre-pass program (see photon_pass.h).
#include "photonmap/photon_pass.h"

#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "common/parallel/gather_to_root.h"
#include "common/parallel/runtime.h"
#include "raytrace/integrators/trace_loop.h"

namespace pr::pm {

namespace {

// Program pixels per image row (the virtual image is kWidth wide).
constexpr int kWidth = 1024;
// Photons per image-space task: a 64 x 64 tile of the virtual image.
constexpr int kTilePx = 64;

// A photon one PE stored, keyed by (map, photon index, bounce): the key order is the batch
// tracer's merge order.
struct StoredPhoton {
  std::uint64_t key = 0;
  Photon photon;
  glm::vec3 normal{0.0f};
};
constexpr std::size_t kStoredBytes = sizeof(Photon) + sizeof(glm::vec3);  // on the wire: photon + normal

std::uint64_t keyOf(PhotonMapKind map, std::uint32_t index, int bounce) {
  return (std::uint64_t(map) << 62) | (std::uint64_t(index) << 8) | std::uint64_t(std::min(bounce, 255));
}

// RayMessage fields as the program uses them: pixel = program pixel (the photon), depth = the
// interaction the ray leads to (bounce), throughput = the photon's power, bsdfPdf = the range
// of its punctual light while depth is 0 (applied at the first hit; 0 = none), sample = the
// PhotonPath bits of the reflections so far.
class PhotonProgram final : public rt::IntegratorBase<PhotonProgram> {
 public:
  PhotonProgram(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                const PhotonSource& source, int pes)
      : IntegratorBase(scene, camera, width, height, rt::IntegratorOptions{}),
        source_(source),
        global_(source.emitted(PhotonMapKind::Global)),
        total_(global_ + source.emitted(PhotonMapKind::Caustic)),
        perPe_(std::size_t(pes)) {}

  std::string_view name() const override { return "photon-pass"; }
  // A photon that leaves the scene is lost; it adds nothing (the program's film is one pixel).
  void miss(const rt::RayMessage&, rt::Emit&) const override {}

  void cameraRays(const rt::PixelRect& rect, int, std::vector<rt::RayMessage>& out) const override {
    for (int y = rect.y0; y < rect.y1; ++y)
      for (int x = rect.x0; x < rect.x1; ++x) {
        const std::size_t p = std::size_t(y) * std::size_t(kWidth) + std::size_t(x);
        if (p >= total_) return;
        EmittedPhoton photon;
        if (!source_.emit(mapOf(p), indexOf(p), photon)) continue;
        rt::RayMessage m;
        m.ray = photon.ray;
        m.throughput = photon.power;
        m.pixel = std::uint32_t(p);
        m.depth = 0;
        m.kind = rt::RayKind::Continuation;
        m.bsdfPdf = photon.range;
        out.push_back(m);
      }
  }

  void shade(const rt::SurfaceInteraction& si, const rt::RayMessage& msg, rt::Emit& out) const override {
    const PhotonMapKind map = mapOf(msg.pixel);
    const std::uint32_t index = indexOf(msg.pixel);
    rt::Hit hit;
    hit.t = si.t;
    const PhotonInteraction step =
        source_.interact(map, index, msg.depth, msg.throughput, msg.depth == 0 ? msg.bsdfPdf : 0.0f,
                         std::uint8_t(msg.sample), msg.ray, hit, si);
    PerPe& mine = perPe_[std::size_t(out.pe())];
    if (step.stored) {
      mine.stored.push_back({keyOf(map, index, msg.depth), step.photon, step.normal});
      ++mine.counts[map == PhotonMapKind::Global ? 2 : 3];
    }
    if (!step.continues || msg.depth >= 254) return;
    rt::RayMessage next = msg;
    next.ray = step.next;
    next.throughput = step.power;
    next.depth = std::uint8_t(msg.depth + 1);
    next.bsdfPdf = 0.0f;
    next.sample = step.path;
    out.push(next);
  }

  struct alignas(64) PerPe {
    std::vector<StoredPhoton> stored;
    std::array<std::uint64_t, 4> counts{};
  };
  std::vector<PerPe>& perPe() const { return perPe_; }

 private:
  PhotonMapKind mapOf(std::size_t p) const { return p < global_ ? PhotonMapKind::Global : PhotonMapKind::Caustic; }
  std::uint32_t indexOf(std::size_t p) const { return std::uint32_t(p < global_ ? p : p - global_); }

  const PhotonSource& source_;
  std::size_t global_, total_;
  mutable std::vector<PerPe> perPe_;  // each PE writes its own (Emit::pe)
};

}  // namespace

PhotonLists tracePhotonMessages(const scene::Scene& scene, const scene::Camera& camera, const PhotonOptions& options,
                                rt::PrePassTracer& tracer, par::Runtime& rt) {
  const PhotonSource source(scene, options);
  PhotonLists out;
  out.stats = source.plan();
  const std::size_t total = out.stats.globalEmitted + out.stats.causticEmitted;
  std::vector<std::array<std::uint64_t, 4>> counts(std::size_t(rt.pes()), std::array<std::uint64_t, 4>{});
  counts[0][0] = out.stats.globalEmitted;
  counts[0][1] = out.stats.causticEmitted;
  std::vector<std::vector<StoredPhoton>> perPe(std::size_t(rt.pes()));
  if (total > 0) {
    const int height = int((total + kWidth - 1) / kWidth);
    const auto program = std::make_shared<const PhotonProgram>(scene, camera, kWidth, height, source, rt.pes());
    tracer.trace(program, kTilePx);
    for (int p = 0; p < rt.pes(); ++p) {
      PhotonProgram::PerPe& mine = program->perPe()[std::size_t(p)];
      counts[std::size_t(p)][2] = mine.counts[2];
      counts[std::size_t(p)][3] = mine.counts[3];
      perPe[std::size_t(p)] = std::move(mine.stored);
    }
    out.stats.tasks = std::size_t(((kWidth + kTilePx - 1) / kTilePx) * ((height + kTilePx - 1) / kTilePx));
  }
  recordPhotonCounters(rt, counts, out.stats);
  // The stored photons travel to PE 0, which puts them in photon order (across ranks rank 0
  // then sends them to every other rank, where the same maps are built from them).
  std::vector<std::vector<StoredPhoton>> merged =
      par::gatherToAll(rt, "photon merge", "photons", par::MessageKind::Data, std::move(perPe), kStoredBytes);
  std::vector<StoredPhoton> all;
  for (std::vector<StoredPhoton>& v : merged) all.insert(all.end(), v.begin(), v.end());
  std::sort(all.begin(), all.end(), [](const StoredPhoton& a, const StoredPhoton& b) { return a.key < b.key; });
  for (const StoredPhoton& s : all) {
    const bool global = (s.key >> 62) == std::uint64_t(PhotonMapKind::Global);
    (global ? out.global : out.caustic).push_back(s.photon);
    (global ? out.globalNormals : out.causticNormals).push_back(s.normal);
  }
  out.stats.globalStored = out.global.size();
  out.stats.causticStored = out.caustic.size();
  return out;
}

}  // namespace pr::pm
