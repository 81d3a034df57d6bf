// DataManager: owner lookup, per-PE LRU cache of remote items, exact hit/miss counts for a
// known access sequence, prefetch, and the fetch traffic: requests and replies through Channels,
// each item served by its owner's PE.
#include <doctest/doctest.h>

#include <cstdint>

#include <atomic>
#include <string>

#include "common/parallel/data_manager.h"

using namespace pr::par;

TEST_CASE("DataManager: owner lookup by blocks and cyclic") {
  const OwnerMap blocks = OwnerMap::blocks(10, 3);
  CHECK(blocks.owner(0) == 0);
  CHECK(blocks.owner(3) == 0);
  CHECK(blocks.owner(4) == 1);
  CHECK(blocks.owner(9) == 2);
  const OwnerMap cyclic = OwnerMap::cyclic(10, 3);
  CHECK(cyclic.owner(4) == 1);
  CHECK(cyclic.owner(9) == 0);
}

TEST_CASE("DataManager: LRU cache keeps the most recently used items") {
  DataCache<int> cache(2);
  cache.insert(1, 10);
  cache.insert(2, 20);
  REQUIRE(cache.find(1) != nullptr);  // 1 is now most recent
  cache.insert(3, 30);                // evicts 2
  CHECK(cache.find(2) == nullptr);
  CHECK(*cache.find(1) == 10);
  CHECK(*cache.find(3) == 30);
  CHECK(cache.size() == 2);
}

TEST_CASE("DataManager: a byte budget evicts least recently used items until the new one fits") {
  // Items are strings of their own length in bytes; 10 bytes of cache, any number of items.
  DataCache<std::string> cache(SIZE_MAX, 10, [](const std::string& v) { return v.size(); });
  cache.insert(1, std::string(4, 'a'));
  cache.insert(2, std::string(4, 'b'));
  CHECK(cache.usedBytes() == 8u);
  REQUIRE(cache.find(1) != nullptr);    // 1 is now most recent
  cache.insert(3, std::string(5, 'c'));  // 13 > 10: evicts 2, then 9 bytes
  CHECK(cache.find(2) == nullptr);
  CHECK(cache.find(1) != nullptr);
  CHECK(cache.usedBytes() == 9u);
  cache.insert(4, std::string(10, 'd'));  // needs the whole cache
  CHECK(cache.size() == 1u);
  CHECK(cache.usedBytes() == 10u);
  CHECK(!cache.fits(std::string(11, 'e')));  // larger than the cache: never held
  cache.insert(4, std::string(2, 'f'));       // replacing an item counts its new size only
  CHECK(cache.usedBytes() == 2u);
}

TEST_CASE("DataManager: hit and miss counts are exact for a known access sequence") {
  // Items 0..9 on PE 1 (blocks of 5: 0-4 on PE 0, 5-9 on PE 1). PE 0 reads remote items with a
  // cache of 2: 5 miss, 6 miss, 5 hit, 7 miss (evicts 6), 6 miss (evicts 5), 5 miss (evicts 7),
  // local 0 (not counted), then prefetch 8 and 9 (evict 6 and 5) and read them: 2 hits.
  // In all 3 hits and 5 misses.
  Runtime rt(2, "balanced");
  std::vector<std::string> partition(10);
  for (int i = 0; i < 10; ++i) partition[i] = std::string(static_cast<std::size_t>(i + 1), 'x');
  DataManager<std::string> data(
      rt, "strings", OwnerMap::blocks(10, 2), 2, [&](Pe&, ItemId item) { return partition[item]; },
      [](const std::string& s) { return s.size(); });
  std::string seen;
  rt.runStage("read", TaskSet::uniform(2), [&](Pe& pe, TaskId) {
    if (pe.id() != 0) return;
    for (ItemId item : {5, 6, 5, 7, 6, 5, 0}) seen += std::to_string(data.acquire(pe, item).size()) + " ";
    data.prefetch(pe, {8, 9, 0});
    for (ItemId item : {8, 9}) seen += std::to_string(data.acquire(pe, item).size()) + " ";
  });
  CHECK(seen == "6 7 6 8 7 6 1 9 10 ");
  CHECK(data.hits(0) == 3);
  CHECK(data.misses(0) == 5);
  const PeStageRecord& pe0 = rt.record().stages[0].pes[0];
  const PeStageRecord& pe1 = rt.record().stages[0].pes[1];
  CHECK(pe0.cacheHits == 3);
  CHECK(pe0.cacheMisses == 5);
  CHECK(pe0.prefetches == 2);
  // 7 fetches (5 misses + 2 prefetches): a request each from PE 0, a reply each from PE 1
  // carrying the item, in fetch order 5, 6, 7, 6, 5, 8, 9 (item i has i + 1 bytes).
  CHECK(pe0.messagesSent == 7);
  CHECK(pe0.bytesSent == 7 * kItemRequestBytes);
  CHECK(pe1.messagesSent == 7);
  CHECK(pe1.bytesSent == 6u + 7 + 8 + 7 + 6 + 9 + 10);
  CHECK(pe0.bytesReceived == pe1.bytesSent);
}

TEST_CASE("DataManager: items are served by their owner's PE through counted channels, PEs fetching from each other") {
  // 12 items cyclic over 3 PEs (item i on PE i mod 3). Every PE reads every item once: 8 remote
  // reads each, all misses (cache of 16), so 8 requests of 16 bytes and 8 replies of 8 bytes
  // (sizeof(long)) per PE, each reply sent by the owner's PE from inside its request handler.
  Runtime rt(3, "balanced");
  std::atomic<int> servedElsewhere{0};
  DataManager<long> data(rt, "numbers", OwnerMap::cyclic(12, 3), 16, [&](Pe& owner, ItemId item) {
    if (static_cast<int>(item % 3) != owner.id()) ++servedElsewhere;
    return static_cast<long>(item * item);
  });
  std::vector<long> sums(3, 0);
  rt.runOnEachPe("read", [&](Pe& pe) {
    for (ItemId item = 0; item < 12; ++item) sums[static_cast<std::size_t>(pe.id())] += data.acquire(pe, item);
  });
  CHECK(servedElsewhere == 0);
  for (long s : sums) CHECK(s == 506);  // sum of i^2 for i < 12
  const StageRecord& stage = rt.record().stages[0];
  for (int p = 0; p < 3; ++p) {
    const PeStageRecord& r = stage.pes[static_cast<std::size_t>(p)];
    CHECK(r.cacheMisses == 8u);
    CHECK(r.cacheHits == 0u);
    CHECK(r.messagesSent == 16u);  // its 8 requests and the 8 replies it served
    CHECK(r.bytesSent == 8u * kItemRequestBytes + 8u * sizeof(long));
    CHECK(r.messagesHandled >= 8u);
  }
  REQUIRE(stage.channels.size() == 2u);
  for (const ChannelTraffic& c : stage.channels) {
    CHECK(c.messages == 24u);
    CHECK(c.kind == (c.name == "numbers requests" ? "requests" : "data"));
  }
}
