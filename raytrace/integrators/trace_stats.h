// TraceStats: rays traced by kind, the algorithm counters of a trace ("Rays/camera", ...),
// counted by the message loops (trace_loop.h, the partitioned tracers) and summed over PEs.
#pragma once

#include <cstdint>

namespace pr::rt {

struct TraceStats {
  uint64_t cameraRays = 0;
  uint64_t continuationRays = 0;
  uint64_t shadowRays = 0;
  uint64_t total() const { return cameraRays + continuationRays + shadowRays; }
  TraceStats& operator+=(const TraceStats& o) {
    cameraRays += o.cameraRays;
    continuationRays += o.continuationRays;
    shadowRays += o.shadowRays;
    return *this;
  }
};

}  // namespace pr::rt
