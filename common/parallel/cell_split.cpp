// The cell splits of cell_split.h.
#include "common/parallel/cell_split.h"

#include <algorithm>
#include <string>

#include "common/util/error.h"

namespace pr::par {

bool isCellSplit(std::string_view split) { return split == kRoundRobinCells || split == kStripCells; }

int cellOwner(std::string_view split, int cell, int cells, int pes) {
  PR_CHECK(cell >= 0 && cell < cells && pes >= 1, "cellOwner: cell " + std::to_string(cell) + " of " + std::to_string(cells));
  if (split == kRoundRobinCells) return cell % pes;
  PR_CHECK(split == kStripCells, "cellOwner: unknown split '" + std::string(split) + "'");
  // The run i whose first cell i n / count is the last one at or before `cell`.
  const long long count = std::min(pes, cells);
  long long i = (static_cast<long long>(cell) * count) / cells;
  while ((i + 1) * cells / count <= cell) ++i;
  while (i * cells / count > cell) --i;
  return static_cast<int>(i);
}

}  // namespace pr::par
