// Spinning busy work of known length, for tests and benchmarks: occupies the calling PE's
// core for the given time on the monotonic clock, without sleeping (a sleep would free the
// core and make busy time meaningless as a measure of work).
#pragma once

#include <chrono>

namespace pr::par {

inline void spinFor(double seconds) {
  using Clock = std::chrono::steady_clock;
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
  }
}

}  // namespace pr::par
