// See farm_replay.h.
#include "common/parallel/farm/farm_replay.h"

#include <algorithm>
#include <deque>
#include <queue>
#include <tuple>

#include "common/util/error.h"

namespace pr::par {

FarmPrediction predictFarm(const FarmRecord& farm, const TaskSet& tasks, std::size_t jobBytes, int servers,
                           const NetworkModel& network, Scheduler& order, const ScheduleParams& params) {
  if (servers < 1) throw InputError("a farm needs at least one server");
  if (tasks.size() != farm.jobs.size()) throw InputError("the farm record's jobs and its jobs stage differ in number");
  for (const FarmJobRecord& j : farm.jobs)
    if (j.server < 1) throw InputError("the farm record's job " + std::to_string(j.job) + " was never done");
  FarmPrediction p;
  p.servers = servers;
  for (const FarmServerRecord& s : farm.servers) p.prepareSeconds += s.prepareSeconds;
  if (!farm.servers.empty()) p.prepareSeconds /= double(farm.servers.size());
  p.serverBusySeconds.assign(std::size_t(servers), 0.0);

  order.reset(tasks, servers, params);
  struct Server {
    std::deque<std::pair<int, double>> held;  // job, arrival
    std::deque<TaskId> granted;
    bool done = false;  // the schedule has nothing more for it
    double freeAt = 0.0;
    bool working = false;
  };
  std::vector<Server> state(static_cast<std::size_t>(servers));
  // Events: (time, server, job): a job finished (job >= 0), or a result received (job = -1 - job).
  using Event = std::tuple<double, int, int>;
  std::priority_queue<Event, std::vector<Event>, std::greater<>> events;
  const double start = p.prepareSeconds;

  const auto nextJob = [&](int s) -> int {
    Server& sv = state[std::size_t(s)];
    while (!sv.done) {
      if (sv.granted.empty()) {
        Grab grab;
        order.next(s, 0.0, grab);
        if (grab.tasks.empty()) {
          sv.done = true;
          break;
        }
        sv.granted.assign(grab.tasks.begin(), grab.tasks.end());
      }
      const int j = int(sv.granted.front());
      sv.granted.pop_front();
      return j;
    }
    return -1;
  };
  const auto startNext = [&](int s) {
    Server& sv = state[std::size_t(s)];
    if (sv.working || sv.held.empty()) return;
    const auto [job, arrival] = sv.held.front();
    sv.held.pop_front();
    const double begin = std::max(sv.freeAt, arrival);
    const double cost = farm.jobs[std::size_t(job)].busySeconds;
    sv.freeAt = begin + cost;
    sv.working = true;
    p.serverBusySeconds[std::size_t(s)] += cost;
    events.emplace(sv.freeAt, s, job);
  };
  const auto send = [&](int s, double at) {
    const int j = nextJob(s);
    if (j < 0) return;
    state[std::size_t(s)].held.emplace_back(j, at + network.seconds(1, jobBytes));
  };
  for (int s = 0; s < servers; ++s) {
    state[std::size_t(s)].freeAt = start;
    for (int k = 0; k < farm.jobsAhead; ++k) send(s, start);
    startNext(s);
  }
  double masterFree = start, last = start;
  while (!events.empty()) {
    const auto [time, s, code] = events.top();
    events.pop();
    Server& sv = state[std::size_t(s)];
    if (code >= 0) {
      // A result leaves the server; it reaches the master after the results ahead of it.
      sv.working = false;
      const std::size_t bytes = farm.jobs[std::size_t(code)].resultBytes;
      const double begin = std::max(time, masterFree);
      const double wire = network.seconds(0, bytes);
      masterFree = begin + wire;
      p.masterLinkSeconds += wire;
      events.emplace(masterFree + network.latencySeconds, s, -1 - code);
      startNext(s);
    } else {
      last = std::max(last, time);
      send(s, time);
      startNext(s);
    }
  }
  p.jobsSeconds = last - start;
  p.makespanSeconds = last;
  return p;
}

}  // namespace pr::par
