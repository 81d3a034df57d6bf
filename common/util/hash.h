// Integer hashing for deterministic pseudo-random decisions that must not depend on the order
// work is done in (sample streams, stochastic transparency): the same inputs give the same
// value on every PE, under every schedule.
#pragma once

#include <cstdint>

namespace pr {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mix with full avalanche.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// The top 24 bits of a hash as a float in [0, 1).
inline float unitFloat(uint64_t h) { return float(h >> 40) * 0x1.0p-24f; }

}  // namespace pr
