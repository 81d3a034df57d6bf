// Running programs under mpirun in tests: on loopback (--oversubscribe), root allowed as in CI,
// every command bounded by `timeout` so a failure can never hang the suite.
#pragma once

#include <cstddef>
#include <string>

#include "test_support.h"

namespace pr::test {

// What every mpirun here is started with: root allowed (CI runs as root), and, in the ASan job,
// no leak check in the ranks: Open MPI unloads its components before exit and leaves
// allocations LeakSanitizer cannot attribute (frames in no loaded module); address and UB
// checks stay on.
inline const std::string kMpiEnv =
    "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ASAN_OPTIONS=\"$ASAN_OPTIONS:detect_leaks=0\" ";

// mpirun -np N PROGRAM ARGS, ended after `limit` seconds at most (timeout's status 124).
inline CommandResult mpirun(int ranks, const std::string& program, const std::string& args, int limit = 60,
                            const std::string& env = "") {
  return runCommand(kMpiEnv + env + " timeout " + std::to_string(limit) + " mpirun --oversubscribe -np " +
                    std::to_string(ranks) + " " + program + " " + args);
}

// How many times `what` occurs in `text` (a message printed once, not once per rank).
inline std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace pr::test
