// Where each method and schedule sits in the seed course's classification (chapters 2 to 5 of
// the SIGGRAPH 2000 notes): task subdivision (screen space or object space; for polygons where
// the sort happens, after Molnar et al.; for ray tracing image space, object space or object
// partitioning, §5.1), the computational model and task management of the schedule (§3.2-3.4),
// and the data management (world model, replicated maps, data manager with caches, §4). The
// report prints these classes beside the figures measured on the scene that define them.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pr::cli::report {

struct MethodClass {
  std::string subdivision;     // "screen space: image tiles" ...
  std::string sortPoint;       // polygons: "sort-first" ...; ray tracing: "-"
  std::string dataManagement;  // "world model: the scene replicated on every PE (§4.1)" ...
  std::string definingFigure;  // which measured figure shows the class ("ray messages per ray")
  std::string seedSection;     // "§5.1.2"
};

struct ScheduleClass {
  std::string model;           // "demand driven (§3.2.2), serial order"
  std::string taskManagement;  // "central task pool on PE 0" ...
};

// Throws pr::InputError for a name the registries do not know.
MethodClass classifyMethod(std::string_view method);
ScheduleClass classifySchedule(std::string_view schedule);

// What a measured run of a method sent, as the class's claims speak of it.
struct MeasuredTraffic {
  int pes = 1;
  std::uint64_t rayMessages = 0, primitiveMessages = 0;
  double compositedBytes = 0.0;  // the Sort/composite_bytes counter
};

// The class's claim about traffic checked against a measured run of the method at P > 1, with
// what the measurement shows: "holds: ", "CONTRADICTED: " (image-space, whose rays never leave
// their PE, sent some), or "not shown here: " (object-space and object send rays, sort-first
// and sort-middle primitives, sort-last composites pixels, but this run sent none: one PE may
// have had all the work); "-" when the run cannot say (P = 1, or a claim the record cannot check).
std::string checkClaim(std::string_view method, const MeasuredTraffic& run);

}  // namespace pr::cli::report
