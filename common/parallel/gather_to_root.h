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

}  // namespace pr::par
