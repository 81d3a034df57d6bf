// gatherToRoot: each PE's list of results moved to one PE as one counted message per PE, the
// transfer a distributed-memory system makes to merge per-PE results before building
// something from all of them (the photon maps from the photons each PE stored, the cache
// records from the gather samples). Runs a stage of its own on the controlling thread.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/parallel/channel.h"
#include "common/parallel/runtime.h"

namespace pr::par {

// perPe[p]: PE p's items. Stage `stage`: every PE but root sends its (non-empty) list to root
// on Channel `channel` of `kind`, counted as bytesPerItem per item; returns the lists indexed
// by their source PE, as root holds them afterwards.
template <class T>
std::vector<std::vector<T>> gatherToRoot(Runtime& rt, std::string_view stage, std::string channel, MessageKind kind,
                                         std::vector<std::vector<T>> perPe, std::size_t bytesPerItem, int root = 0) {
  struct Batch {
    int from = 0;
    std::vector<T> items;
  };
  std::vector<std::vector<T>> out(perPe.size());
  Channel<Batch> ch(rt, std::move(channel), kind, [&out](Pe&, Batch&& b) { out[std::size_t(b.from)] = std::move(b.items); });
  rt.runOnEachPe(stage, [&](Pe& pe) {
    std::vector<T>& mine = perPe[std::size_t(pe.id())];
    if (pe.id() == root) {
      out[std::size_t(root)] = std::move(mine);
    } else if (!mine.empty()) {
      const std::size_t bytes = mine.size() * bytesPerItem;
      ch.sendDeclared(pe, root, Batch{pe.id(), std::move(mine)}, bytes);
    }
  });
  return out;
}

}  // namespace pr::par
