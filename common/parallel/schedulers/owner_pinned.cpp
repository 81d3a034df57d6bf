// Owner-pinned scheduling: each task runs on the PE that owns its data (a screen region, a
// voxel, a PE's own buffers), so the assignment is the data distribution's, not a strategy's.
// Each PE takes its own portion where it is, like the data-driven portions (seed 3.2.1; no
// packet is sent); Runtime::runPinned and runOnEachPe are its users, and the stage record keeps
// the owners.
#include <string>

#include "common/parallel/schedulers/scheduler.h"
#include "common/parallel/schedulers/static_portions.h"
#include "common/util/error.h"

namespace pr::par {

std::unique_ptr<Scheduler> makeOwnerPinnedScheduler(std::vector<int> owner) {
  return std::make_unique<StaticPortionScheduler>(
      kOwnerPinnedSchedule, [owner = std::move(owner)](const TaskSet& tasks, int pes) {
        PR_CHECK(tasks.size() == owner.size(), "owner-pinned schedule: " + std::to_string(tasks.size()) +
                                                   " tasks, " + std::to_string(owner.size()) + " owners");
        std::vector<std::vector<TaskId>> portions(static_cast<std::size_t>(pes));
        for (std::size_t t = 0; t < owner.size(); ++t) {
          PR_CHECK(owner[t] >= 0 && owner[t] < pes,
                   "owner-pinned schedule: task " + std::to_string(t) + " owned by PE " + std::to_string(owner[t]));
          portions[static_cast<std::size_t>(owner[t])].push_back(static_cast<TaskId>(t));
        }
        return portions;
      });
}

}  // namespace pr::par
