// RayMessage: one ray plus the path state it carries, the unit of work every tracer moves
// (sequential queue, image-space tile loop, object-space and object-partitioning Channels).
// Integrators make them (camera rays, shading) and consume them (shade, miss); a tracer only
// decides where each one is traced. Trivially copyable: sizeof is the message's bytes.
#pragma once

#include <cstdint>
#include <type_traits>

#include <glm/glm.hpp>

#include "raytrace/core/ray.h"

namespace pr::rt {

enum class RayKind : uint8_t {
  Camera,        // primary ray from the eye
  Continuation,  // reflection, refraction or path bounce: shaded where it hits
  Shadow,        // visibility test: adds `throughput` to the pixel iff unoccluded
  Gather,        // final-gathering ray: shaded where it hits, by the integrator's gather rule
                 // (photon map: the global map's estimate); traced and counted as a continuation
};

struct RayMessage {
  Ray ray;
  // Path weight; for a shadow ray the radiance it adds to its pixel when unoccluded.
  glm::vec3 throughput{1.0f};
  uint32_t pixel = 0;       // y * width + x
  uint16_t sample = 0;      // index within the pixel's spp
  uint8_t depth = 0;        // surface interactions before this ray (camera ray = 0)
  RayKind kind = RayKind::Camera;
  // Solid-angle pdf of the BSDF sample that made this ray, for multiple importance sampling
  // of the emitter it may hit; 0 after a specular (delta) event or for camera rays, which
  // count emission fully; negative after a rough bounce whose vertex sampled the lights
  // without MIS, so that the light it reaches counts not at all.
  float bsdfPdf = 0.0f;
};

static_assert(std::is_trivially_copyable_v<RayMessage>, "RayMessage travels through Channels");
static_assert(sizeof(RayMessage) == 56, "RayMessage bytes are the message volume; keep it compact");

}  // namespace pr::rt
