// PerPe: one value per PE, no two PEs' values on one cache line (the point of the type: a
// PE's appends and counter increments never take a line away from another PE), kept across
// resize, and copied out in PE order.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "common/parallel/per_pe.h"

using namespace pr::par;

namespace {
uintptr_t lineOf(const void* p) { return reinterpret_cast<uintptr_t>(p) / kCacheLineBytes; }
}  // namespace

TEST_CASE("PerPe: small values of different PEs never share a cache line") {
  PerPe<uint64_t> counters(4);
  PerPe<std::vector<int>> lists(4);
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      // A value spans [first byte, last byte]; no line may hold bytes of two PEs' values.
      CHECK(lineOf(&counters[a]) != lineOf(&counters[b]));
      CHECK(lineOf(reinterpret_cast<const char*>(&lists[a]) + sizeof(std::vector<int>) - 1) < lineOf(&lists[b]));
    }
}

TEST_CASE("PerPe: values survive growing and come out in PE order") {
  PerPe<int> v(2);
  v[0] = 7;
  v[1] = 9;
  v.resize(3);
  CHECK(v.size() == 3);
  CHECK(v.values() == std::vector<int>{7, 9, 0});
}
