// Data management for partitioned data (seed chapter 4): every data item (voxel contents,
// object set, photon-map block) has an owner PE; a PE that needs a remote item gets it through
// its DataManager, which keeps a per-PE cache of remote items (LRU, fixed capacity), counts
// hits and misses, fetches items known in advance (prefetch), and counts every fetch as a
// request message to the owner and a reply message from it, in the running stage.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/parallel/pe.h"
#include "common/parallel/runtime.h"
#include "common/util/error.h"

namespace pr::par {

using ItemId = std::uint64_t;

// Bytes of a fetch request (item id + requesting PE), as a distributed implementation sends it.
inline constexpr std::size_t kItemRequestBytes = 16;

// Owner lookup by item id.
class OwnerMap {
 public:
  explicit OwnerMap(std::vector<int> owners) : owners_(std::move(owners)) {}
  // Contiguous blocks, the first items mod P PEs one item more (as balancedSplit).
  static OwnerMap blocks(std::size_t items, int pes) {
    std::vector<int> owners(items);
    const std::size_t base = items / pes, extra = items % pes;
    std::size_t i = 0;
    for (int p = 0; p < pes; ++p)
      for (std::size_t k = 0; k < base + (static_cast<std::size_t>(p) < extra ? 1 : 0); ++k) owners[i++] = p;
    return OwnerMap(std::move(owners));
  }
  // Item i on PE i mod P: spreads spatially coherent hot spots over PEs.
  static OwnerMap cyclic(std::size_t items, int pes) {
    std::vector<int> owners(items);
    for (std::size_t i = 0; i < items; ++i) owners[i] = static_cast<int>(i % pes);
    return OwnerMap(std::move(owners));
  }
  int owner(ItemId item) const {
    PR_CHECK(item < owners_.size(), "OwnerMap: item id out of range");
    return owners_[item];
  }
  std::size_t size() const { return owners_.size(); }

 private:
  std::vector<int> owners_;
};

// A cache of remote items on one PE, least recently used evicted first. Used by one PE only.
template <class T>
class DataCache {
 public:
  explicit DataCache(std::size_t capacity) : capacity_(capacity) {}

  // The cached item, marked most recently used; nullptr when absent.
  const T* find(ItemId item) {
    auto it = index_.find(item);
    if (it == index_.end()) return nullptr;
    order_.splice(order_.begin(), order_, it->second);
    return &it->second->second;
  }
  const T& insert(ItemId item, T value) {
    PR_CHECK(capacity_ > 0, "DataCache: insert into a cache of capacity 0");
    if (auto it = index_.find(item); it != index_.end()) {
      it->second->second = std::move(value);
      order_.splice(order_.begin(), order_, it->second);
      return it->second->second;
    }
    if (order_.size() == capacity_) {
      index_.erase(order_.back().first);
      order_.pop_back();
    }
    order_.emplace_front(item, std::move(value));
    index_[item] = order_.begin();
    return order_.front().second;
  }
  bool contains(ItemId item) const { return index_.count(item) > 0; }
  std::size_t size() const { return order_.size(); }
  std::size_t capacity() const { return capacity_; }

 private:
  std::size_t capacity_;
  std::list<std::pair<ItemId, T>> order_;  // front = most recently used
  std::unordered_map<ItemId, typename std::list<std::pair<ItemId, T>>::iterator> index_;
};

template <class T>
class DataManager {
 public:
  // Reads item from its owner's partition: the copy is the transfer. Called on the requesting
  // PE's thread; the owner's partition must be read-only during the stage.
  using Loader = std::function<T(int owner, ItemId item)>;
  using ByteSize = std::function<std::size_t(const T&)>;

  DataManager(int pes, OwnerMap owners, std::size_t cacheCapacity, Loader load, ByteSize bytes = {})
      : owners_(std::move(owners)), load_(std::move(load)), bytes_(std::move(bytes)) {
    for (int p = 0; p < pes; ++p) caches_.emplace_back(cacheCapacity);
    local_.resize(pes);
    hits_.assign(pes, 0);
    misses_.assign(pes, 0);
  }

  int owner(ItemId item) const { return owners_.owner(item); }

  // On PE pe inside a task or handler: the item, from pe's own partition, its cache (a hit) or
  // its owner (a miss: one request and one reply message). The reference stays valid until pe's
  // next acquire or prefetch. Items of pe's own partition are neither hits nor misses.
  const T& acquire(Pe& pe, ItemId item) {
    const int owner = owners_.owner(item);
    if (owner == pe.id()) return local_[pe.id()] = load_(owner, item);
    DataCache<T>& cache = caches_[pe.id()];
    if (const T* cached = cache.find(item)) {
      ++hits_[pe.id()];
      pe.counters().cacheHits.fetch_add(1, std::memory_order_relaxed);
      return *cached;
    }
    ++misses_[pe.id()];
    pe.counters().cacheMisses.fetch_add(1, std::memory_order_relaxed);
    return fetch(pe, owner, item);
  }

  // Fetches items known in advance (a data-driven portion, a preferred-bias region) into pe's
  // cache, so that later acquires hit. Counted as prefetches and messages, not as misses.
  void prefetch(Pe& pe, const std::vector<ItemId>& items) {
    for (ItemId item : items) {
      const int owner = owners_.owner(item);
      if (owner == pe.id() || caches_[pe.id()].contains(item)) continue;
      pe.counters().prefetches.fetch_add(1, std::memory_order_relaxed);
      fetch(pe, owner, item);
    }
  }

  std::uint64_t hits(int pe) const { return hits_[pe]; }
  std::uint64_t misses(int pe) const { return misses_[pe]; }
  const DataCache<T>& cache(int pe) const { return caches_[pe]; }

 private:
  const T& fetch(Pe& pe, int owner, ItemId item) {
    T value = [&] {
      const SendReceiveTimer timer(pe);
      return load_(owner, item);
    }();
    const std::size_t bytes = bytes_ ? bytes_(value) : sizeof(T);
    pe.runtime().countMessage(pe.id(), owner, kItemRequestBytes);
    pe.runtime().countMessage(owner, pe.id(), bytes);
    if (caches_[pe.id()].capacity() == 0) return local_[pe.id()] = std::move(value);
    return caches_[pe.id()].insert(item, std::move(value));
  }

  OwnerMap owners_;
  Loader load_;
  ByteSize bytes_;
  std::vector<DataCache<T>> caches_;  // one per PE, touched only by that PE
  std::vector<T> local_;
  std::vector<std::uint64_t> hits_, misses_;
};

}  // namespace pr::par
