// Pass 1 of Jensen's two-pass method: photons leave every light, are traced through the scene
// with Russian roulette, and are stored in the global map (every diffuse hit) and the caustic
// map (the first diffuse hit after one or more specular bounces, photons aimed at specular
// objects by a projection map). Batches of photons are tasks on the runtime; each photon's
// random stream is a function of (seed, map, photon index) only, so the maps are the same for
// every P and schedule. Seed chapter "Global Illumination in Complex Scenes using Photon
// Maps", sections 2.1-2.2; Jensen, "Realistic Image Synthesis Using Photon Mapping", ch. 5.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/scene/effect_analysis.h"
#include "common/scene/scene.h"
#include "photonmap/kd_tree.h"
#include "photonmap/photon.h"

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
  // Indirect off: no global photon is traced (pass 2 reads the global map only for indirect
  // diffuse light).
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

// The stored photons in merge order (batch by batch, photon by photon): what the kd-trees are
// built from. Exposed so that tests can compare runs photon for photon.
struct PhotonLists {
  std::vector<Photon> global;
  std::vector<Photon> caustic;
  PhotonStats stats;
};

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
