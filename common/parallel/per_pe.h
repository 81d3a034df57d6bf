// PerPe<T>: one T per PE, each on cache lines of its own, for the state a PE writes in its
// inner loops (the triangle list it appends to, its counters). In a plain std::vector<T> the
// Ts of neighbouring PEs share a cache line when T is small (a vector's header is 24 bytes, a
// tally of counters 24-48), and every write by one PE then takes the line away from the other
// (false sharing): on the 2-core machine, per-triangle appends to neighbouring lists cost
// sort-last's render stage at P = 2 about a third of its time.
#pragma once

#include <cstddef>
#include <vector>

namespace pr::par {

inline constexpr std::size_t kCacheLineBytes = 64;

template <class T>
class PerPe {
 public:
  PerPe() = default;
  explicit PerPe(int pes) : slots_(static_cast<std::size_t>(pes)) {}

  // Keeps the Ts of PEs below the new count (their storage too).
  void resize(int pes) { slots_.resize(static_cast<std::size_t>(pes)); }
  int size() const { return static_cast<int>(slots_.size()); }

  T& operator[](int pe) { return slots_[static_cast<std::size_t>(pe)].value; }
  const T& operator[](int pe) const { return slots_[static_cast<std::size_t>(pe)].value; }

  // The Ts in PE order, copied: what the run record and the counters read after a stage.
  std::vector<T> values() const {
    std::vector<T> out;
    out.reserve(slots_.size());
    for (const Slot& s : slots_) out.push_back(s.value);
    return out;
  }

 private:
  struct alignas(kCacheLineBytes) Slot {
    T value{};
  };
  std::vector<Slot> slots_;
};

}  // namespace pr::par
