// Errors at the boundary and checks inside (shared/DESIGN.md, rule 6).
// InputError: bad user input (file, option, scene content); the CLI prints its message and
// exits with status 2. PR_CHECK: a broken internal invariant, a programming error: abort.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace pr {

// Thrown where input enters (loader, CLI); the message names the file/element and the problem.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Exit status for bad input, shared by every subcommand.
inline constexpr int kExitBadInput = 2;

[[noreturn]] inline void checkFailed(const char* cond, const char* file, int line, const std::string& what) {
  std::fprintf(stderr, "parrender: internal check failed: %s at %s:%d %s\n", cond, file, line, what.c_str());
  std::abort();
}

}  // namespace pr

// PR_CHECK(cond, message-string): always on; for invariants outside hot loops.
#define PR_CHECK(cond, ...) \
  do { \
    if (!(cond)) ::pr::checkFailed(#cond, __FILE__, __LINE__, std::string(__VA_ARGS__)); \
  } while (0)

// PR_DCHECK: debug builds only, for hot loops.
#ifdef NDEBUG
#define PR_DCHECK(cond, ...) do { (void)sizeof(cond); } while (0)
#else
#define PR_DCHECK(cond, ...) PR_CHECK(cond, __VA_ARGS__)
#endif
