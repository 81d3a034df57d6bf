// One fresh, timed render (see timed_render.h).
#include "tools/timed_render.h"

#include <sys/resource.h>

#include <chrono>
#include <utility>

namespace pr::cli {

double processCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

TimedRender timedRender(const RenderMethod& method, const RenderInput& input, const RenderSettings& settings, int pes,
                        const par::ScheduleOptions& schedule, std::function<void(int64_t, int64_t)> progress) {
  par::Runtime runtime(par::RuntimeOptions{pes, schedule.schedule, schedule.params, true});
  const RenderRequest request{input.scene, input.camera, input.width,      input.height,
                              settings,    input.plan,   runtime,          std::move(progress)};
  const double cpu0 = processCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  TimedRender t;
  t.outcome = method.make(method.name, request);
  t.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.cpuSeconds = processCpuSeconds() - cpu0;
  t.record = runtime.record();
  return t;
}

}  // namespace pr::cli
