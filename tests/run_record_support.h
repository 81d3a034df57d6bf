// Reading a run record's counters in tests: the figures leave every renderer only as named
// per-PE counters (STYLE.md section 4), so tests of every library read them the same way.
#pragma once

#include <cstddef>
#include <string>

#include "common/parallel/run_record.h"

namespace pr::test {

// The named per-PE counter of the run record, summed over PEs (pe < 0) or of one PE; 0 when
// it was never recorded.
inline double counterTotal(const par::RunRecord& record, const std::string& name, int pe = -1) {
  double sum = 0.0;
  for (const par::CounterRecord& c : record.counters) {
    if (c.name != name) continue;
    for (std::size_t p = 0; p < c.perPe.size(); ++p)
      if (pe < 0 || int(p) == pe) sum += c.perPe[p];
  }
  return sum;
}

}  // namespace pr::test
