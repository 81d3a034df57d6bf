// Data management for partitioned data (seed chapter 4): every data item (voxel contents,
// object set, photon-map block) has an owner PE; a PE that needs a remote item gets it through
// its DataManager, which keeps a per-PE cache of remote items (LRU, fixed capacity), counts
// hits and misses, fetches items known in advance (prefetch); every fetch is a request message
// to the owner and a reply message from it, both through Channels, served by the owner's PE.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <algorithm>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "common/parallel/await_reply.h"
#include "common/parallel/channel.h"
#include "common/parallel/per_pe.h"
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

// A cache of remote items on one PE, least recently used evicted first, holding at most
// `capacity` items and, when a size function is given, at most `capacityBytes` bytes of them.
// Used by one PE only.
template <class T>
class DataCache {
 public:
  using ByteSize = std::function<std::size_t(const T&)>;
  DataCache() : DataCache(0) {}  // holds nothing
  explicit DataCache(std::size_t capacity, std::size_t capacityBytes = SIZE_MAX, ByteSize bytes = {})
      : capacity_(capacity), capacityBytes_(capacityBytes), bytes_(std::move(bytes)) {}

  // The cached item, marked most recently used; nullptr when absent.
  const T* find(ItemId item) {
    auto it = index_.find(item);
    if (it == index_.end()) return nullptr;
    order_.splice(order_.begin(), order_, it->second);
    return &it->second->value;
  }
  // Whether an item of this size can be held at all (alone, after evicting everything else).
  bool fits(const T& value) const { return capacity_ > 0 && sizeOf(value) <= capacityBytes_; }
  const T& insert(ItemId item, T value) {
    PR_CHECK(fits(value), "DataCache: insert of an item larger than the cache");
    const std::size_t size = sizeOf(value);
    if (auto it = index_.find(item); it != index_.end()) {
      usedBytes_ -= it->second->bytes;
      order_.erase(it->second);
      index_.erase(it);
    }
    while (!order_.empty() && (order_.size() >= capacity_ || usedBytes_ + size > capacityBytes_)) {
      usedBytes_ -= order_.back().bytes;
      index_.erase(order_.back().item);
      order_.pop_back();
    }
    order_.push_front(Entry{item, std::move(value), size});
    usedBytes_ += size;
    index_[item] = order_.begin();
    return order_.front().value;
  }
  bool contains(ItemId item) const { return index_.count(item) > 0; }
  std::size_t size() const { return order_.size(); }
  std::size_t capacity() const { return capacity_; }
  std::size_t usedBytes() const { return usedBytes_; }

 private:
  struct Entry {
    ItemId item;
    T value;
    std::size_t bytes;
  };
  std::size_t sizeOf(const T& value) const { return bytes_ ? bytes_(value) : 0; }

  std::size_t capacity_, capacityBytes_;
  ByteSize bytes_;
  std::size_t usedBytes_ = 0;
  std::list<Entry> order_;  // front = most recently used
  std::unordered_map<ItemId, typename std::list<Entry>::iterator> index_;
};

// The reply to a fetch request: the item and when it is usable (runtime time of the requester,
// for the simulated latency).
template <class T>
struct ItemReply {
  ItemId item = 0;
  T value{};
  double readyAt = 0.0;
};

// On the wire: item id, readyAt, then the item as Wire<T> encodes it.
template <class T>
  requires HasWire<T>
struct Wire<ItemReply<T>> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const ItemReply<T>& r) { return sizeof r.item + sizeof r.readyAt + Wire<T>::size(r.value); }
  static void encode(const ItemReply<T>& r, WireWriter& w) {
    w.value(r.item);
    w.value(r.readyAt);
    Wire<T>::encode(r.value, w);
  }
  static ItemReply<T> decode(WireReader& r) { return decode(r, Wire<T>::decode); }
  // The same with the item decoded by `value` (an item type whose decoding needs the receiver's
  // context: DataManager::decodeItemsWith).
  template <class DecodeValue>
  static ItemReply<T> decode(WireReader& r, DecodeValue&& value) {
    ItemReply<T> reply;
    reply.item = r.value<ItemId>();
    reply.readyAt = r.value<double>();
    reply.value = value(r);
    return reply;
  }
};

// Items of a partition move only as messages: a PE that misses sends a request ("<name>
// requests", kind requests) to the item's owner, whose PE serves it in a message handler from
// its own partition and sends the item back ("<name> items", kind data). The requesting PE
// waits inside its task for the reply (booked as message waiting, not busy) and serves the
// messages of every handled channel sent to it meanwhile (await_reply.h), so PEs fetching from
// each other always make progress. An
// owner busy in a long task answers at its next task boundary, as a single-threaded PE of a
// distributed-memory machine would.
template <class T>
class DataManager {
 public:
  // Reads item from the owner's own partition, on the owner's PE (inside its request handler,
  // or for an item of the requester's own partition, on the requester).
  using Loader = std::function<T(Pe& owner, ItemId item)>;
  using ByteSize = std::function<std::size_t(const T&)>;

  // Created between stages, like any Channel. The cache holds at most cacheCapacity items and
  // cacheBytes bytes of them (by `bytes`); an item larger than that is used once and dropped.
  DataManager(Runtime& runtime, const std::string& name, OwnerMap owners, std::size_t cacheCapacity, Loader load,
              ByteSize bytes = {}, std::size_t cacheBytes = SIZE_MAX)
      : owners_(std::move(owners)),
        load_(std::move(load)),
        bytes_(std::move(bytes)),
        items_(runtime, name + " items", MessageKind::Data),
        requests_(runtime, name + " requests", MessageKind::Requests,
                  [this](Pe& owner, Request&& r) { serve(owner, r); }) {
    pe_.resize(runtime.pes());
    for (int p = 0; p < runtime.pes(); ++p) pe_[p].cache = DataCache<T>(cacheCapacity, cacheBytes, bytes_);
  }

  int owner(ItemId item) const { return owners_.owner(item); }

  // Across ranks, for an item type whose decoding needs the receiver's context (the scene):
  // how an item that arrived from another rank is made from its encoding. Between stages.
  void decodeItemsWith(std::function<T(WireReader&)> decode) {
    items_.decodeWith([decode = std::move(decode)](WireReader& r) { return Wire<Reply>::decode(r, decode); });
  }

  // A simulated one-way network latency for requests and replies: a reply is usable no sooner
  // than 2 x latency after its request was sent (later when the owner was busy). Between
  // stages.
  void setLatency(double seconds) { latency_ = seconds; }

  // On PE pe inside a task: the item, from pe's own partition, its cache (a hit) or its owner
  // (a miss: one request and one reply message). The reference stays valid until pe's next
  // acquire or prefetch. Items of pe's own partition are neither hits nor misses.
  const T& acquire(Pe& pe, ItemId item) {
    const int owner = owners_.owner(item);
    if (owner == pe.id()) return pe_[pe.id()].local = load_(pe, item);
    DataCache<T>& cache = pe_[pe.id()].cache;
    if (const T* cached = cache.find(item)) {
      ++pe_[pe.id()].hits;
      pe.counters().cacheHits.fetch_add(1, std::memory_order_relaxed);
      return *cached;
    }
    ++pe_[pe.id()].misses;
    pe.counters().cacheMisses.fetch_add(1, std::memory_order_relaxed);
    requests_.sendDeclared(pe, owner, Request{item, pe.id(), pe.runtime().now()}, kItemRequestBytes);
    Reply reply = awaitReply(pe);
    PR_CHECK(reply.item == item, "DataManager: a reply for another item");
    waitUntilReady(pe, reply);
    if (!cache.fits(reply.value)) return pe_[pe.id()].local = std::move(reply.value);
    return cache.insert(item, std::move(reply.value));
  }

  // On PE pe inside a task: fetches items known in advance (a data-driven portion, a
  // preferred-bias region) into pe's cache, all requests first, so that later acquires hit.
  // Counted as prefetches and messages, not as misses.
  void prefetch(Pe& pe, const std::vector<ItemId>& items) {
    std::size_t asked = 0;
    for (ItemId item : items) {
      const int owner = owners_.owner(item);
      if (owner == pe.id() || pe_[pe.id()].cache.contains(item)) continue;
      pe.counters().prefetches.fetch_add(1, std::memory_order_relaxed);
      requests_.sendDeclared(pe, owner, Request{item, pe.id(), pe.runtime().now()}, kItemRequestBytes);
      ++asked;
    }
    for (; asked > 0; --asked) {
      Reply reply = awaitReply(pe);
      waitUntilReady(pe, reply);
      if (pe_[pe.id()].cache.fits(reply.value)) pe_[pe.id()].cache.insert(reply.item, std::move(reply.value));
    }
  }

  // Latency hiding (seed section 4.5.2): the non-blocking form of acquire for a PE that has
  // other work (other rays, other tiles) to do while an item travels. A remote item's pointer
  // when it is cached or has just arrived (a hit when countHit), else nullptr after sending its
  // request unless one is out already (a miss, counted once per request; the others as
  // joined(pe)). The pointer stays
  // valid until pe's next awaitArrival. Items of pe's own partition go through acquire.
  const T* tryAcquire(Pe& pe, ItemId item, bool countHit = true) {
    Async& a = pe_[pe.id()].async;
    if (a.heldValid && a.heldItem == item) return &a.held;
    if (const T* cached = pe_[pe.id()].cache.find(item)) {
      if (countHit) {
        ++pe_[pe.id()].hits;
        pe.counters().cacheHits.fetch_add(1, std::memory_order_relaxed);
      }
      return cached;
    }
    if (a.outstanding.insert(item).second) {
      ++pe_[pe.id()].misses;
      pe.counters().cacheMisses.fetch_add(1, std::memory_order_relaxed);
      requests_.sendDeclared(pe, owners_.owner(item), Request{item, pe.id(), pe.runtime().now()}, kItemRequestBytes);
    } else {
      ++a.joined;  // a miss whose item is already on its way: no second request
    }
    return nullptr;
  }

  // Blocks (serving the messages sent to pe meanwhile, booked as waiting) until one of pe's
  // outstanding items has arrived and is usable; puts it in the cache, or holds it until the
  // next awaitArrival when it does not fit, and returns its id.
  ItemId awaitArrival(Pe& pe) {
    Async& a = pe_[pe.id()].async;
    PR_CHECK(!a.outstanding.empty(), "DataManager: awaiting an arrival with no request out");
    a.heldValid = false;
    a.held = T{};
    Runtime& rt = pe.runtime();
    ItemId arrived = 0;
    waitUntil(pe, kWhat, [&] {
      Reply reply;
      while (items_.tryReceive(pe, reply)) a.travelling.push_back(std::move(reply));
      auto ready = std::min_element(a.travelling.begin(), a.travelling.end(),
                                    [](const Reply& x, const Reply& y) { return x.readyAt < y.readyAt; });
      if (ready == a.travelling.end() || ready->readyAt > rt.now()) return false;
      Reply r = std::move(*ready);
      a.travelling.erase(ready);
      a.outstanding.erase(r.item);
      if (pe_[pe.id()].cache.fits(r.value)) {
        pe_[pe.id()].cache.insert(r.item, std::move(r.value));
      } else {
        a.held = std::move(r.value);
        a.heldItem = r.item;
        a.heldValid = true;
      }
      arrived = r.item;
      return true;
    });
    return arrived;
  }

  std::uint64_t hits(int pe) const { return pe_[pe].hits; }
  // tryAcquire calls that missed an item already requested (no message of their own).
  std::uint64_t joined(int pe) const { return pe_[pe].async.joined; }
  std::uint64_t misses(int pe) const { return pe_[pe].misses; }
  const DataCache<T>& cache(int pe) const { return pe_[pe].cache; }

 private:
  struct Request {
    ItemId item;
    int requester;
    double sentAt = 0.0;  // runtime time, for the simulated latency
  };
  using Reply = ItemReply<T>;
  // Per PE: the requests of tryAcquire still out, the replies received but still travelling
  // (simulated latency), and the last arrival the cache could not hold.
  struct Async {
    std::unordered_set<ItemId> outstanding;
    std::vector<Reply> travelling;
    T held{};
    ItemId heldItem = 0;
    bool heldValid = false;
    std::uint64_t joined = 0;
  };

  // On the owner's PE, in the request handler: the item from its own partition, sent back.
  void serve(Pe& owner, const Request& r) {
    // A request from another rank is checked, not trusted.
    if (r.requester < 0 || r.requester >= owner.runtime().pes() || r.item >= owners_.size() ||
        owners_.owner(r.item) != owner.id())
      throw WireError("a data request for an item this PE does not own, or from no PE");
    const double now = owner.runtime().now();
    // A requester on another rank reads readyAt on its own clock: its request's time plus the
    // two latencies (the owner's busy time there is real, not simulated).
    const double readyAt = owner.runtime().isLocal(r.requester) ? std::max(now, r.sentAt + latency_) + latency_
                                                                 : r.sentAt + 2.0 * latency_;
    Reply reply{r.item, load_(owner, r.item), readyAt};
    const std::size_t bytes = bytes_ ? bytes_(reply.value) : sizeof(T);
    items_.sendDeclared(owner, r.requester, std::move(reply), bytes);
  }

  inline static const std::string kWhat = "a data item";
  Reply awaitReply(Pe& pe) { return par::awaitReply(pe, items_, kWhat); }

  // The simulated latency of a reply already received: waits (serving messages, booked as
  // waiting) until it is usable.
  void waitUntilReady(Pe& pe, const Reply& reply) {
    Runtime& rt = pe.runtime();
    waitUntil(pe, kWhat, [&] { return rt.now() >= reply.readyAt; });
  }

  OwnerMap owners_;
  Loader load_;
  ByteSize bytes_;
  Channel<Reply> items_;
  Channel<Request> requests_;
  // What each PE touches on every acquire, its own only (on cache lines of its own: a cache
  // hit reorders the LRU list, whose head lives in the DataCache object).
  struct PeData {
    DataCache<T> cache;
    T local{};
    Async async;
    std::uint64_t hits = 0, misses = 0;
  };
  PerPe<PeData> pe_;
  double latency_ = 0.0;
};

}  // namespace pr::par
