// StageReplay: how the simulator (simulator.cpp) replays one recorded stage at P' PEs — which
// strategy hands out its tasks, which tasks there are and on which PE they are pinned, and how
// much message-handler and set-up work each PE does — or why it cannot say, so the stage is left out of
// the prediction. The rules for owner-pinned stages (Runtime::runPinned, runOnEachPe) say how
// the method would split its data at P', from what the record holds:
//
//   as recorded   P' = the recorded P: the recorded owners and task costs.
//   cells         a stage whose PEs' work is made of cells dealt by a rule of P (cell_split.h:
//                 screen tiles dealt round-robin, rows in strips): the cells are dealt again at P',
//                 each with its measured seconds; the rest of the PEs' work (binning, geometry
//                 of what a PE draws) is split evenly, as each PE's. Every cell off the
//                 collector sends its result there (its recorded bytes), and the collector
//                 stores it at the record's seconds per byte of stored results (none known from
//                 a record in which every cell was on the collector: then not charged, and the
//                 note says so).
//   each PE in full  a stage the record names "each PE in full" (a full-screen buffer each PE
//                 clears): P' tasks, each the recorded mean (an upper bound where the work
//                 shrinks with the PE's share).
//   each PE       owners 0..P-1, one task per PE (build my BVHs, clear my buffers, composite my
//                 rectangle): P' tasks of total/P' each. Assumes the work divides evenly over
//                 owners, as the cost-balanced voxel and object splits and the strip regions
//                 intend; wrong for per-PE work that does not shrink with P (a full-frame
//                 buffer on every PE) and for rounds whose count depends on P (binary swap).
//   round-robin   owners[t] = t mod P with more tasks than PEs (screen regions dealt out):
//                 re-dealt t mod P'. Assumes the set of regions does not depend on P.
//   single owner  every task on one PE q < P' (work done once by a designated PE, e.g. the
//                 world BVH built on the assembler's PE): kept on q at any P'. A stage the
//                 record names "one PE" (runOnOnePe, runOncePerRank) is this, whatever its
//                 owners look like: at P = 1 it cannot be told from each-PE work otherwise, and
//                 once per rank it is one copy's work (the longest) done side by side.
//   one PE        P' = 1: every task on the one PE (a single owner holds all the data).
//   excluded      any other owner list follows a data distribution the record does not
//                 describe (e.g. voxels assigned by cost): no prediction at P' for that stage.
//
// Stages with a strategy are replayed with it: the --schedule given to simulate for stages that
// ran under the run's own schedule, the recorded one for stages with a fixed strategy (the
// image-space cost pre-pass is always "balanced").
//
// Message handlers: at the recorded P each PE keeps its recorded handler work; at another P'
// the stage's total (seconds, messages handled, messages and bytes sent) is divided evenly over
// the P' PEs, i.e. the messages go to owners that hold equal shares of the data. Set-ups (the
// PEs' owner-local preparation at the start of a stage) follow the same rule: as recorded at
// P, else the total over P' (the each-PE rule's assumption: the data divides evenly). Data messages
// (sent by tasks or handlers) are the recorded ones, except at P' = 1, where every message
// would go to the PE itself and none is charged. A P = 1 record has none, so it predicts no
// data traffic at P' > 1; a record at P predicts its own message count at every P' > 1,
// although a partitioned method's count grows with P (more owners, more boundaries crossed).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "common/parallel/simulator.h"

namespace pr::par {

enum class ReplayRule { Scheduled, AsRecorded, Cells, EachPeInFull, EachPe, RoundRobin, SingleOwner, OnePe, Excluded };
// "scheduled", "as recorded", "cells", "each PE in full", "each PE", "round-robin", "single owner",
// "one PE", "excluded".
std::string_view replayRuleName(ReplayRule rule);

struct StageReplay {
  ReplayRule rule = ReplayRule::Scheduled;
  std::string schedule;  // registry name, kOwnerPinnedSchedule, or empty when excluded
  bool runtimeSchedule = false;  // Scheduled under the run's own schedule (or the --schedule one)
  std::string note;      // the rule's assumption, or why the stage is excluded
  SimStage stage;        // the stage at P': tasks, costs, messages; owners for pinned rules
  std::vector<HandlerLoad> handlers;  // P' entries, zero when the stage handled no messages
  std::vector<SetupLoad> setups;      // P' entries, zero when the stage has no set-up
};

// Called by simulate() for each stage. recordedPes = 0 for a cost table. schedule: the strategy
// for stages that ran under the run's own schedule, empty = as recorded.
// Throws pr::InputError when the stage ends up with no strategy at all.
StageReplay planReplay(const SimStage& stage, int recordedPes, int pes, std::string_view schedule);

}  // namespace pr::par
