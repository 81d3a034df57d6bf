// Demand-driven (dynamic) region assignment: tiles are handed to PEs by the runtime's
// scheduler as they ask for work, so no owner is known when the sort happens. Each PE keeps
// what it binned per tile; the PE that takes a tile asks every other PE for its bin of that
// tile (a request message each) and receives it as a reply message. Used by sort-first
// (primitive ids) and sort-middle (screen triangles); all traffic goes through Channels.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/parallel/await_reply.h"
#include "common/parallel/channel.h"

namespace pr::raster {

// Bin: a tile's bin as one PE holds it and sends it, a message type with size() (its items):
// std::vector<ScreenTriangle> for sort-middle, PrimitiveBatch for sort-first.
template <class Bin>
class TilePull {
 public:
  // bins[pe][tile]: what PE pe binned for each tile; a PE reads and moves out its own only.
  // A reply is counted as its encoding.
  TilePull(par::Runtime& runtime, const std::string& name, std::vector<std::vector<Bin>>& bins)
      : runtime_(runtime),
        bins_(bins),
        name_(name),
        sent_(runtime.pes(), 0),
        replies_(runtime, name + " replies", par::MessageKind::Primitives),
        requests_(runtime, name + " requests", par::MessageKind::Requests, [this](par::Pe& pe, Request&& r) {
          Bin& bin = bins_[pe.id()][r.tile];
          sent_[pe.id()] += bin.size();
          replies_.send(pe, r.pe, std::move(bin));
        }) {}

  // Inside the task for `tile` on pe: its own bin, then every other PE's as they arrive. While it
  // waits for replies the PE answers the requests sent to it, so PEs waiting on each other
  // always make progress. When another PE's task fails the runtime aborts the stage and that
  // PE never replies: gather throws instead of waiting forever (the runtime keeps the first
  // error, so the original failure is what runStage rethrows).
  std::vector<Bin> gather(par::Pe& pe, int tile) {
    const int pes = runtime_.pes();
    std::vector<Bin> parts;
    parts.reserve(size_t(pes));
    parts.push_back(std::move(bins_[pe.id()][tile]));
    for (int p = 0; p < pes; ++p)
      if (p != pe.id()) requests_.send(pe, p, Request{tile, pe.id()});
    const std::string what = "'" + name_ + "': the bins of tile " + std::to_string(tile);
    for (int got = 0; got < pes - 1; ++got) parts.push_back(par::awaitReply(pe, replies_, what));
    return parts;
  }

  // Items each PE sent to another PE (sum over its replies).
  uint64_t itemsSent(int pe) const { return sent_[pe]; }

 private:
  struct Request {
    int32_t tile;
    int32_t pe;
  };

  par::Runtime& runtime_;
  std::vector<std::vector<Bin>>& bins_;
  std::string name_;
  std::vector<uint64_t> sent_;  // per PE, written by that PE's handler only
  par::Channel<Bin> replies_;
  par::Channel<Request> requests_;
};

}  // namespace pr::raster
