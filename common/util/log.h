// Warnings and progress for long runs. Warnings go to stderr once each and are also kept,
// so run records and `info --json` can list them (an optional feature we ignore is never silent).
#pragma once

#include <string>
#include <vector>

namespace pr {

// Prints "parrender: warning: <message>" to stderr unless quiet mode is set.
void warn(const std::string& message);

// Suppresses warning output (for tests and --quiet); warnings are still returned by the caller.
void setQuiet(bool quiet);
bool quiet();

}  // namespace pr
