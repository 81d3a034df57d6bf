// Helpers for the photon-map tests: a small deterministic random stream (the same numbers
// with every standard library) and photon sets with known properties.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "photonmap/photon.h"

namespace pr::test {

// splitmix64 (Steele et al. 2014): enough for test data, identical everywhere.
class TestRng {
 public:
  explicit TestRng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float uniform() { return static_cast<float>(next() >> 40) * 0x1p-24f; }  // [0, 1)
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  glm::vec3 inBox(float lo, float hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }

 private:
  std::uint64_t state_;
};

inline std::vector<pm::Photon> randomPhotons(std::size_t n, std::uint64_t seed, float lo = -1.0f, float hi = 1.0f) {
  TestRng rng(seed);
  std::vector<pm::Photon> photons(n);
  for (std::size_t i = 0; i < n; ++i)
    photons[i] = pm::Photon::make(rng.inBox(lo, hi), glm::vec3(1.0f), glm::vec3(0.0f, 0.0f, 1.0f));
  return photons;
}

}  // namespace pr::test
