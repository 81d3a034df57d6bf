// One fresh, timed render (see timed_render.h).
#include "tools/timed_render.h"

#include <chrono>
#include <string>
#include <utility>

#include "common/parallel/process_group.h"
#include "common/util/error.h"

namespace pr::cli {

std::string Placement::acrossRanks() const {
  if (ranks == 1) return {};
  return " (" + std::to_string(ranks) + " ranks x " + std::to_string(pes / ranks) + " PEs)";
}

Placement everyRank(int threadsPerRank) {
  const int ranks = par::ProcessGroup::get().ranks();
  return Placement{ranks * threadsPerRank, ranks};
}

bool holdsResults() { return par::ProcessGroup::get().rank() == 0; }

namespace {

TimedRender render(const RenderMethod& method, const RenderInput& input, const RenderSettings& settings, Placement where,
                   const par::ScheduleOptions& schedule, std::function<void(int64_t, int64_t)> progress) {
  par::ProcessGroup& group = par::ProcessGroup::get();
  par::Transport* transport = where.ranks > 1 ? &group.transport() : nullptr;
  par::Runtime runtime(par::RuntimeOptions{where.pes, schedule.schedule, schedule.params, true, transport});
  const RenderRequest request{input.scene, input.camera, input.width,      input.height,
                              settings,    input.plan,   runtime,          std::move(progress)};
  const double cpu0 = processCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  TimedRender t;
  t.outcome = method.make(method.name, request);
  t.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double cpu = processCpuSeconds() - cpu0;
  runtime.sumAcrossRanks(std::span<double>(&cpu, 1), group.timeoutSeconds());  // every rank's PEs
  t.cpuSeconds = cpu;
  t.record = runtime.record();
  return t;
}

}  // namespace

TimedRender timedRender(const RenderMethod& method, const RenderInput& input, const RenderSettings& settings,
                        Placement where, const par::ScheduleOptions& schedule,
                        std::function<void(int64_t, int64_t)> progress) {
  par::ProcessGroup& group = par::ProcessGroup::get();
  PR_CHECK(where.ranks == 1 || (where.ranks == group.ranks() && where.pes % where.ranks == 0),
           "a render runs on one rank or on every rank, the same number of PEs on each");
  if (where.ranks > 1 || group.ranks() == 1) return render(method, input, settings, where, schedule, std::move(progress));
  TimedRender t;
  group.onRank0Alone(method.name + " on rank 0 alone", [&] {
    t = render(method, input, settings, where, schedule, std::move(progress));
    return par::Bytes();
  });
  return t;
}

}  // namespace pr::cli
