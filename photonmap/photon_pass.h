// Pass 1 as ray messages: photon tracing run through the render's own tracer (rt::PrePassTracer),
// so that in object-space and object partitioning a photon's path travels between the owners
// of the geometry it meets, as rays do, and in image-space batches of photons are tasks. The
// program's virtual image has one pixel per photon (the global map's first, then the caustic
// map's); each pixel's "camera ray" is its photon leaving the light, and each hit is one
// interaction of PhotonSource, the same functions the batch tracer (photon_tracer.h) runs, so
// the stored photons are the same whichever tracer and P. Every PE keeps the photons it
// stored; they travel to PE 0 as counted messages (stage "photon merge"), are put in photon
// order and built into the two kd-trees there, and the maps are then broadcast to every PE.
#pragma once

#include "photonmap/photon_tracer.h"

namespace pr::rt {
class PrePassTracer;
}

namespace pr::pm {

// Traces both maps' photons through `tracer` on rt's PEs and merges them on PE 0 in photon
// order (the order tracePhotonLists gives). Records the Photons/... counters; stored photons
// per PE where they were stored, emissions on PE 0 (the emission plan is the controller's).
PhotonLists tracePhotonMessages(const scene::Scene& scene, const scene::Camera& camera, const PhotonOptions& options,
                                rt::PrePassTracer& tracer, par::Runtime& rt);

}  // namespace pr::pm
