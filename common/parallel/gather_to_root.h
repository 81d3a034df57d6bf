// gatherToRoot: each PE's list of results moved to one PE as one counted message per PE, the
// transfer a distributed-memory system makes to merge per-PE results before building
// something from all of them (the photon maps from the photons each PE stored, the cache
// records from the gather samples). Runs a stage of its own on the controlling thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/parallel/channel.h"
#include "common/parallel/runtime.h"
#include "common/parallel/wire.h"

namespace pr::par {

// One PE's list on its way to the root: its source and items.
template <class T>
struct GatheredList {
  std::int32_t from = 0;
  std::vector<T> items;
};

// On the wire: the source (4 bytes), then the items as they lie in memory, so a list can
// leave its rank.
template <class T>
  requires std::is_trivially_copyable_v<T>
struct Wire<GatheredList<T>> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const GatheredList<T>& l) { return sizeof(std::int32_t) + l.items.size() * sizeof(T); }
  static void encode(const GatheredList<T>& l, WireWriter& w) {
    w.value(l.from);
    w.elements(std::span<const T>(l.items));
  }
  static GatheredList<T> decode(WireReader& r) {
    GatheredList<T> l;
    l.from = r.value<std::int32_t>();
    l.items = r.elements<T>();
    return l;
  }
};

// perPe[p]: PE p's items. Stage `stage`: every PE but root sends its (non-empty) list to root
// on Channel `channel` of `kind`, counted as bytesPerItem per item; returns the lists indexed
// by their source PE, as root holds them afterwards (across ranks: on root's rank; the other
// ranks get back their lists emptied). Items leave a rank as their bytes, so T is trivially
// copyable there.
template <class T>
std::vector<std::vector<T>> gatherToRoot(Runtime& rt, std::string_view stage, std::string channel, MessageKind kind,
                                         std::vector<std::vector<T>> perPe, std::size_t bytesPerItem, int root = 0) {
  std::vector<std::vector<T>> out(perPe.size());
  Channel<GatheredList<T>> ch(rt, std::move(channel), kind, [&out](Pe&, GatheredList<T>&& b) {
    if (b.from < 0 || std::size_t(b.from) >= out.size()) throw WireError("a gathered list from a PE out of range");
    out[std::size_t(b.from)] = std::move(b.items);
  });
  rt.runOnEachPe(stage, [&](Pe& pe) {
    std::vector<T>& mine = perPe[std::size_t(pe.id())];
    if (pe.id() == root) {
      out[std::size_t(root)] = std::move(mine);
    } else if (!mine.empty()) {
      const std::size_t bytes = mine.size() * bytesPerItem;
      ch.sendDeclared(pe, root, GatheredList<T>{pe.id(), std::move(mine)}, bytes);
    }
  });
  return out;
}

// Inside a stage, on each rank's first PE, across ranks: what rank 0 made reaches every other
// rank as its encoding, booked as that broadcast between ranks (Runtime::broadcastToRanks).
// encode(WireWriter&) runs on rank 0, decode(WireReader&) on the others. Returns the
// encoding's size, on one rank too (encoded there only to be measured, nothing moves), for
// the caller to book what the rank's other PEs read (Runtime::recordBroadcastWithinRanks).
template <class Encode, class Decode>
std::size_t shareEncodedFromRank0(Runtime& rt, Pe& pe, Encode&& encode, Decode&& decode) {
  Bytes bytes;
  if (rt.rank() == 0) {
    WireWriter w(bytes);
    encode(w);
  }
  const std::size_t size = bytes.size();
  if (rt.ranks() == 1) return size;
  rt.broadcastToRanks(pe, bytes);
  if (rt.rank() == 0) return size;
  WireReader r(bytes);
  decode(r);
  return bytes.size();
}

// gatherToRoot to PE 0, then PE 0 broadcasts the lists to every other PE, so every rank
// returns the lists indexed by source PE: what a pre-pass needs where every PE then derives
// the same thing from them (a photon map, the records of a cache), a replicated computation.
// Across ranks they travel from rank 0 to every other rank in a stage of their own (`stage` +
// " share": a real broadcast of their encoding, booked as one copy per other rank); within a
// rank the other PEs read the rank's copy (booked as a broadcast per PE). So P - 1 copies are
// booked whatever R, on one rank too, where nothing moves: the same record on any transport.
template <class T>
  requires std::is_trivially_copyable_v<T>
std::vector<std::vector<T>> gatherToAll(Runtime& rt, std::string_view stage, std::string channel, MessageKind kind,
                                        std::vector<std::vector<T>> perPe, std::size_t bytesPerItem) {
  std::vector<std::vector<T>> out = gatherToRoot(rt, stage, std::move(channel), kind, std::move(perPe), bytesPerItem);
  if (rt.ranks() > 1)
    rt.runOncePerRank(std::string(stage) + " share", [&](Pe& pe) {
      (void)shareEncodedFromRank0(
          rt, pe,
          [&](WireWriter& w) {
            for (const std::vector<T>& list : out) w.sequence(std::span<const T>(list));
          },
          [&](WireReader& r) {
            for (std::vector<T>& list : out) list = r.sequence<T>();
            if (r.remaining() != 0) throw WireError("rank 0's gathered lists have bytes left over");
          });
    });
  std::size_t bytes = 0;  // the lists' encoding, as every rank now holds them
  for (const std::vector<T>& list : out) bytes += sizeof(std::uint64_t) + list.size() * sizeof(T);
  rt.recordBroadcastWithinRanks(bytes);
  return out;
}

// After a stage in which the task that owns index i wrote values[i] on whichever PE ran it:
// every PE gets every value, each PE's values gathered to PE 0 and shared (gatherToAll), on
// one rank as across ranks (where the values are in place already, they are booked as the
// same messages and broadcast, so the record does not depend on the transport). writer(i): the
// PE of this rank that wrote values[i], or -1 (another rank's). Nothing for one PE.
template <class T, class Writer>
  requires std::is_trivially_copyable_v<T>
void shareWrittenValues(Runtime& rt, std::string_view stage, std::string channel, std::vector<T>& values,
                        Writer&& writer) {
  if (rt.pes() == 1) return;
  struct At {
    std::uint32_t index;
    T value;
  };
  std::vector<std::vector<At>> perPe(std::size_t(rt.pes()));
  for (std::size_t i = 0; i < values.size(); ++i)
    if (const int p = writer(i); p >= 0) {
      At a{};  // zeroed, padding included: every byte that travels is defined
      a.index = std::uint32_t(i);
      a.value = values[i];
      perPe[std::size_t(p)].push_back(a);
    }
  for (const std::vector<At>& from : gatherToAll(rt, stage, std::move(channel), MessageKind::Data, std::move(perPe), sizeof(At)))
    for (const At& a : from) {
      if (a.index >= values.size()) throw WireError("a shared value's index is out of range");
      values[a.index] = a.value;
    }
}

// A stage of one task per `perTask` consecutive values, task t writing values[i] for its own
// indices (work(pe, t)); every PE then holds every value (shareWrittenValues, in stage
// `mergeStage`). Nothing runs for no values.
template <class T, class Work>
  requires std::is_trivially_copyable_v<T>
void runStageSharingResults(Runtime& rt, const std::string& stage, const std::string& mergeStage, std::string channel,
                            std::vector<T>& values, std::size_t perTask, Work&& work) {
  if (values.empty()) return;
  const std::size_t tasks = (values.size() + perTask - 1) / perTask;
  std::vector<int> ranBy(tasks, -1);  // per task: the PE of this rank that ran it
  rt.runStage(stage, TaskSet::uniform(tasks), [&](Pe& pe, TaskId t) {
    ranBy[std::size_t(t)] = pe.id();
    work(pe, t);
  });
  shareWrittenValues(rt, mergeStage, std::move(channel), values, [&](std::size_t i) { return ranBy[i / perTask]; });
}

}  // namespace pr::par
