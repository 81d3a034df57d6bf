// Cell splits: how a stage whose PEs' work is made of cells (screen tiles, screen rows) deals
// them to P PEs, as a function of P. The method deals its cells by the rule it names in the
// run record (Runtime::describeCells), and the simulator deals the recorded cells by the same
// rule at another P (stage_replay.h), so the split is recomputed, not stretched.
#pragma once

#include <string_view>

namespace pr::par {

// Cell c on PE c mod P (static screen tiles dealt in equal shares).
inline constexpr const char* kRoundRobinCells = "round-robin";
// The n cells (screen rows) cut into min(P, n) runs of equal length, run i, the cells
// [i n / count, (i + 1) n / count), on PE i (sort-last's direct-send strips of equal height);
// PEs beyond n have none.
inline constexpr const char* kStripCells = "strips";

bool isCellSplit(std::string_view split);
// The PE of cell `cell` of `cells` under `split` at `pes` PEs (0 <= cell < cells, pes >= 1).
int cellOwner(std::string_view split, int cell, int cells, int pes);

}  // namespace pr::par
