// Pass 1 of Jensen's two-pass method: photons leave every light, are traced through the scene
// with Russian roulette over each surface's whole BSDF, and are stored in the global map (every
// hit on a surface with a diffuse part) and the caustic map (every such hit after one or more
// specular choices, photons aimed at specular objects by a projection map). Batches of photons
// are tasks on the runtime; each photon's random stream is a function of (seed, map, photon
// index) only, so the maps are the same for every P and schedule. Seed chapter "Global Illumination in Complex Scenes using Photon
// Maps", sections 2.1-2.2; Jensen, "Realistic Image Synthesis Using Photon Mapping", ch. 5.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
#include "photonmap/kd_tree.h"
#include "photonmap/photon.h"
#include "raytrace/core/interaction.h"
#include "raytrace/core/ray.h"

namespace pr::par {
class Runtime;
}
namespace pr::rt {
class Bvh;
}

namespace pr::pm {

struct PhotonOptions {
  std::uint64_t seed = 1;
  std::size_t globalPhotons = 200000;   // emitted for the global map (over all lights)
  std::size_t causticPhotons = 100000;  // emitted towards specular objects for the caustic map
  std::size_t batchSize = 4096;         // photons per task (the task granularity)
  int maxBounces = 64;                  // safety cap on a path; roulette ends paths long before
  bool textures = true;                 // emissive and surface textures (the plan's textures)
  // The effects to simulate (the RenderPlan's). Caustics off: no caustic photon is traced.
  // Indirect and glossy both off: no global photon is traced (pass 2 reads the global map only
  // for indirect diffuse light and at the hits of glossy rays).
  scene::EffectSet effects = scene::EffectSet::all();
};

// What pass 1 did, for the run record and the tests.
struct PhotonStats {
  std::size_t globalEmitted = 0;
  std::size_t causticEmitted = 0;
  std::size_t globalStored = 0;
  std::size_t causticStored = 0;
  std::size_t globalSkipped = 0;    // requested global photons not traced (plan: indirect off)
  std::size_t causticSkipped = 0;   // requested caustic photons not traced (plan: caustics off, or no specular target)
  std::size_t causticTargets = 0;   // bounding spheres of the projection map
  std::size_t tasks = 0;
};

// The stored photons in merge order (photon by photon in index order, each photon's stores in
// bounce order): what the kd-trees are built from, with the geometric normal of the surface
// each was stored on (facing the side it arrived from; precomputed irradiance reads them).
// Exposed so that tests can compare runs photon for photon.
struct PhotonLists {
  std::vector<Photon> global;
  std::vector<Photon> caustic;
  std::vector<glm::vec3> globalNormals;
  std::vector<glm::vec3> causticNormals;
  PhotonStats stats;
};

// A photon as it leaves its light: first ray, power, and the range of its punctual light (the
// range window applies at the first hit; 0 = none).
struct EmittedPhoton {
  rt::Ray ray;
  glm::vec3 power{0.0f};
  float range = 0.0f;
};

// What one surface interaction does with a photon: stores it (on the surface with normal
// `normal`), and continues it along `next` with `power` and the PhotonPath bits of its path so
// far, or ends it.
struct PhotonInteraction {
  bool stored = false;
  Photon photon;
  glm::vec3 normal{0.0f};
  bool continues = false;
  rt::Ray next;
  glm::vec3 power{0.0f};
  std::uint8_t path = 0;
};

// The emitters, projection map and photon split of one pass 1, built once by the controlling
// thread, read-only by every PE: the two steps of a photon's path as functions of (map, photon
// index, bounce), which both the batch tracer below and the message-passing photon pass of the
// photon-map integrator run, so that they store the same photons.
class PhotonSource {
 public:
  PhotonSource(const scene::Scene& scene, const PhotonOptions& options);
  ~PhotonSource();
  PhotonSource(const PhotonSource&) = delete;
  PhotonSource& operator=(const PhotonSource&) = delete;

  // Photons to emit for a map after the plan's skips; the emitted, skipped and target figures.
  std::size_t emitted(PhotonMapKind map) const;
  PhotonStats plan() const;
  // Photon `index` of `map` leaving its light; false when it carries no power (or index is out of range).
  bool emit(PhotonMapKind map, std::size_t index, EmittedPhoton& out) const;
  // Its interaction number `bounce` (0 = the first surface hit) at si, reached along ray with
  // power after the reflections `path` (PhotonPath bits; 0 as it leaves the light).
  PhotonInteraction interact(PhotonMapKind map, std::uint32_t index, int bounce, const glm::vec3& power, float range,
                             std::uint8_t path, const rt::Ray& ray, const rt::Hit& hit,
                             const rt::SurfaceInteraction& si) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The (u, v) that photon j of an emitter's n draws its direction from, given its uniform
// (u, v): the photons 0 .. m^2 - 1 (m = floor(sqrt(n))) each take one jittered cell of an
// m x m grid, the rest are uniform, so every cell's expected share is exactly 1/m^2 for any n.
glm::vec2 stratifiedEmission(std::size_t j, std::size_t n, float u, float v);

// Puts pass 1's figures in the run record: per PE photons emitted and stored by map
// (perPe rows: global emitted, caustic emitted, global stored, caustic stored), and the
// photons the plan skipped (on PE 0). Called between stages.
void recordPhotonCounters(par::Runtime& runtime, const std::vector<std::array<std::uint64_t, 4>>& perPe,
                          const PhotonStats& stats);

struct PhotonMaps {
  KdTree global;
  KdTree caustic;
  PhotonStats stats;
};

// Traces both maps' photons on the runtime (stage "photon trace", one task per batch) and
// merges the per-batch lists in batch order. Called by the controlling thread between stages;
// reads the Scene and Bvh only (replicated, read-only ADI).
PhotonLists tracePhotonLists(const scene::Scene& scene, const rt::Bvh& bvh, const PhotonOptions& options,
                             par::Runtime& runtime);
// tracePhotonLists, then both kd-trees built on the runtime (stage "photon-kd-build").
PhotonMaps tracePhotons(const scene::Scene& scene, const rt::Bvh& bvh, const PhotonOptions& options,
                        par::Runtime& runtime);

}  // namespace pr::pm
