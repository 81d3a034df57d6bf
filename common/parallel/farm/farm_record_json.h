// A farm record (farm_record.h) as JSON: the "farm" object of a run record's JSON
// (run_record_json.cpp), also what `compare --json` gives a farm row.
#pragma once

#include <nlohmann/json.hpp>

#include "common/parallel/farm/farm_record.h"

namespace pr::par {

nlohmann::json farmJson(const FarmRecord& farm);

}  // namespace pr::par
