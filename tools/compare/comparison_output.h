// A comparison (comparison.h) as people and programs read it: the table `parrender compare`
// prints, and the same rows as CSV and JSON (one row per combination; messages and bytes per
// kind; the skipped combinations with their reasons; the image agreement of each row).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "tools/compare/comparison.h"

namespace pr::cli {

// The table: one line per row; message kinds that no row used are left out.
std::string comparisonTable(const Comparison& comparison);
// Skipped combinations and image agreement, a line each.
std::string comparisonNotes(const Comparison& comparison);
std::string comparisonCsv(const Comparison& comparison);
// A number through a printf format ("%.3f"): the figures of the table and of the report.
std::string formatNumber(double v, const char* format);
nlohmann::json comparisonJson(const Comparison& comparison);

}  // namespace pr::cli
