// Demand-driven model with random allocation (seed 3.2.2): a fixed random permutation, so a
// late hot spot is unlikely to be handed out last; the seed's "ensure no task is allocated
// more than once" is the permutation itself.
#include <numeric>

#include "common/parallel/schedulers/demand_pool.h"

namespace pr::par {
namespace {

// splitmix64 (Steele et al. 2014): a fixed, portable stream, unlike std::shuffle's
// implementation-defined use of its engine.
std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace

std::vector<TaskId> randomOrder(const TaskSet& tasks, const ScheduleParams& params) {
  std::vector<TaskId> ids(tasks.size());
  std::iota(ids.begin(), ids.end(), TaskId{0});
  std::uint64_t state = params.seed;
  for (std::size_t i = ids.size(); i > 1; --i) std::swap(ids[i - 1], ids[splitmix64(state) % i]);
  return ids;
}

std::unique_ptr<Scheduler> makeDemandRandom() { return std::make_unique<DemandPoolScheduler>("random", randomOrder); }

}  // namespace pr::par
