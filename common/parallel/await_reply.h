// Waiting inside a task for a reply from another PE (a tile's bins, a data item): the PE keeps
// serving the requests sent to it meanwhile, so PEs waiting on each other always make progress,
// and books the time it spent with nothing to do as message waiting, not busy (Pe::recordWait).
// Used by TilePull (raster dynamic regions) and DataManager.
#pragma once

#include <stdexcept>
#include <string>
#include <thread>

#include "common/parallel/channel.h"

namespace pr::par {

// On PE pe inside a task: the next message of `replies` for pe, answering messages of the
// handled channel `serving` until it comes. When another PE fails, the stage aborts and the
// reply may never come: throws std::runtime_error naming `what` instead of waiting forever (the
// runtime keeps the first error, so the original failure is what runStage rethrows).
// One turn of waiting on PE pe inside a task: answers one message of `serving` if one waits,
// else yields the core and books the time as waiting. Throws when the stage aborts.
inline void serveOrYield(Pe& pe, ChannelBase& serving, const std::string& what) {
  Runtime& rt = pe.runtime();
  if (rt.aborting()) throw std::runtime_error("stage aborted while PE " + std::to_string(pe.id()) + " waited for " + what);
  if (serving.handleOne(pe)) {
    pe.counters().messagesHandled.fetch_add(1, std::memory_order_relaxed);
    rt.outstanding().done();  // the waiting task is still counted, so never the last unit
    return;
  }
  const double t0 = rt.now();
  std::this_thread::yield();
  pe.recordWait(rt.now() - t0);
}

template <class Reply>
Reply awaitReply(Pe& pe, Channel<Reply>& replies, ChannelBase& serving, const std::string& what) {
  Reply reply;
  while (!replies.tryReceive(pe, reply)) serveOrYield(pe, serving, what);
  return reply;
}

}  // namespace pr::par
