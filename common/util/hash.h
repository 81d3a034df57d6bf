// Integer hashing for deterministic pseudo-random decisions that must not depend on the order
// work is done in (sample streams, stochastic transparency): the same inputs give the same
// value on every PE, under every schedule.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pr {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mix with full avalanche.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// FNV-1a over bytes (Fowler, Noll, Vo): a content hash (a file's settings, a scene, a command
// line) that is the same on every machine.
class Fnv1a {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 1099511628211ull;
  }
  uint64_t value() const { return h_; }

 private:
  uint64_t h_ = 1469598103934665603ull;
};

// The top 24 bits of a hash as a float in [0, 1).
inline float unitFloat(uint64_t h) { return float(h >> 40) * 0x1.0p-24f; }

}  // namespace pr
