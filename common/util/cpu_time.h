// The CPU time of this process so far: user plus system seconds of every thread (getrusage).
// What a timed render (tools/timed_render.h) and a farm server (its goodbye) report.
#pragma once

#include <sys/resource.h>

namespace pr {

inline double processCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

}  // namespace pr
