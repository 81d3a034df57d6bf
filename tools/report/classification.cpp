// The seed's classification of each method and schedule (see classification.h). One entry
// per registered name: a method or schedule added without its class here is an error at once.
#include "tools/report/classification.h"

#include <map>

#include "common/util/error.h"

namespace pr::cli::report {

MethodClass classifyMethod(std::string_view method) {
  static const std::map<std::string, MethodClass, std::less<>> kClasses = {
      {"sequential",
       {"none: one task on one PE", "-", "world model: the whole scene in one memory (§4.1)",
        "the serial time Ts the ray tracers' speed-ups are measured against", "§2.4.2"}},
      {"sequential-raster",
       {"none: the sequential raster pipeline, one task on one PE, nothing sorted", "-",
        "world model: the whole scene in one memory (§4.1)",
        "the serial time Ts the sort points' speed-ups are measured against", "§2.4.2"}},
      {"image-space",
       {"screen space: image tiles are the tasks, rays never leave their PE", "-",
        "world model: the scene and its BVH replicated on every PE (§4.1); photon maps replicated",
        "broadcast bytes to each PE but PE 0 (the replicated scene) and no ray messages", "§5.1.2"}},
      {"image-space-cached",
       {"screen space: image tiles are the tasks", "-",
        "data manager: geometry items owned by PEs, fetched on demand into a local LRU cache, prefetched by profile, "
        "latency hidden by switching rays (§4.3, §4.5); photon maps replicated",
        "cache hit ratio and the requests and data messages of the data manager", "§4.3"}},
      {"object-space",
       {"object space: voxels of a kd split of space own their geometry, rays travel between owners", "-",
        "distributed: each PE holds the geometry of its voxels only; shading data and photon maps replicated (§4.6)",
        "ray messages per ray, and load imbalance from where the scene's cost lies", "§5.1.2"}},
      {"object",
       {"object partitioning: objects dealt to PEs, rays query the owners they can reach", "-",
        "distributed: each PE holds its objects; a directory of the owners' bounds and the photon maps replicated",
        "ray messages (queries and hits) per ray", "§5.1.2"}},
      {"sort-first",
       {"screen space: regions of the screen own the primitives that fall in them", "sort-first (before geometry)",
        "primitives migrate to region owners; shading data replicated",
        "primitives sent and duplicated across regions", "§5.1.1"}},
      {"sort-middle",
       {"screen space: regions of the screen own screen triangles", "sort-middle (between geometry and rasterization)",
        "scene replicated for geometry; screen triangles sent to region owners",
        "triangles sent to region owners (primitives messages)", "§5.1.1"}},
      {"sort-last",
       {"object space: every PE renders its primitives full screen", "sort-last (after rasterization)",
        "scene replicated; depth-keyed pixels composited by region",
        "pixels composited (pixels messages) against the analytic b A (1 - 1/P) per PE and a header per message", "§5.1.1"}},
  };
  const auto it = kClasses.find(method);
  if (it == kClasses.end()) throw InputError("report: method " + std::string(method) + " has no class in the seed's classification");
  return it->second;
}

ScheduleClass classifySchedule(std::string_view schedule) {
  static const std::map<std::string, ScheduleClass, std::less<>> kClasses = {
      {"balanced", {"balanced data driven (§3.2.1): equal portions fixed before the run", "none at run time: each PE its portion"}},
      {"unbalanced", {"unbalanced data driven (§3.2.1): portions of equal estimated cost", "none at run time: each PE its portion"}},
      {"demand", {"demand driven (§3.2.2), serial order", "central task pool on the controller (§3.4.2)"}},
      {"spiral", {"demand driven (§3.2.2), spiral order from the image centre", "central task pool on the controller (§3.4.2)"}},
      {"random", {"demand driven (§3.2.2), random order", "central task pool on the controller (§3.4.2)"}},
      {"hot-spots", {"demand driven (§3.2.2), most expensive first", "central task pool on the controller (§3.4.2)"}},
      {"hybrid", {"hybrid (§3.2.3): a static first portion, then on demand", "central task pool for the rest"}},
      {"task-manager", {"demand driven (§3.2.2)", "task manager with a local pool refilled ahead of need (§3.4.3)"}},
      {"distributed", {"demand driven (§3.2.2)", "distributed task management: idle PEs take work from neighbours (§3.4.4)"}},
      {"preferred-bias", {"demand driven (§3.2.2) over conceptual regions", "preferred bias allocation (§3.4.5)"}},
  };
  const auto it = kClasses.find(schedule);
  if (it == kClasses.end()) throw InputError("report: schedule " + std::string(schedule) + " has no class in the seed's classification");
  return it->second;
}

std::string checkClaim(std::string_view method, const MeasuredTraffic& run) {
  if (run.pes < 2) return "-";
  // A class that forbids some traffic is contradicted by any of it; one that implies traffic is
  // only not shown by none (a small image can leave one PE with all the work, or one region).
  const auto none = [](std::uint64_t n, const std::string& measured) {
    return (n == 0 ? "holds: " : "CONTRADICTED: ") + measured;
  };
  const auto some = [](bool any, const std::string& measured) { return (any ? "holds: " : "not shown here: ") + measured; };
  const std::string rays = std::to_string(run.rayMessages) + " ray messages";
  if (method == "image-space") return none(run.rayMessages, rays);
  if (method == "object-space" || method == "object") return some(run.rayMessages > 0, rays);
  if (method == "sort-first" || method == "sort-middle")
    return some(run.primitiveMessages > 0, std::to_string(run.primitiveMessages) + " primitive messages");
  if (method == "sort-last")
    return some(run.compositedBytes > 0.0, std::to_string(std::uint64_t(run.compositedBytes)) + " bytes composited");
  return "-";
}

}  // namespace pr::cli::report
