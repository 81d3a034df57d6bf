// SplitMix64 (Steele, Lea, Flood 2014): the generator's only source of randomness. Its output
// is fixed by the algorithm, unlike std::shuffle or the std distributions, so a seed gives
// byte-identical scene files on every platform and standard library.
#pragma once

#include <cstdint>

namespace pr::scenegen {

class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}

  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

  // Uniform in [0, 1) from the top 24 bits, exact in float.
  float uniform() { return static_cast<float>(next() >> 40) * 0x1p-24f; }

  // Uniform integer in [0, n) by multiply-shift (bias below 2^-32 for the small n used here).
  uint32_t below(uint32_t n) { return static_cast<uint32_t>(((next() >> 32) * n) >> 32); }

 private:
  uint64_t state_;
};

}  // namespace pr::scenegen
