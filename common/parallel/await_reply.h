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
// On PE pe inside a task: polls done() until it returns true, answering the messages of the
// handled channel `serving` meanwhile. A turn that neither finished nor answered a message
// (the poll and the yield) is booked as waiting (Pe::recordWait); answering is busy. Throws
// std::runtime_error naming `what` when the stage aborts.
template <class Done>
void waitUntil(Pe& pe, ChannelBase& serving, const std::string& what, Done&& done) {
  Runtime& rt = pe.runtime();
  double t0 = rt.now();
  while (!done()) {
    if (rt.aborting()) throw std::runtime_error("stage aborted while PE " + std::to_string(pe.id()) + " waited for " + what);
    if (serving.handleOne(pe)) {
      pe.counters().messagesHandled.fetch_add(1, std::memory_order_relaxed);
      rt.outstanding().done();  // the waiting task is still counted, so never the last unit
      t0 = rt.now();
      continue;
    }
    // Across ranks a reply from another rank arrives only while some thread of this one calls
    // the transport: this PE does, rather than wait for the controlling thread's next poll.
    if (!rt.pumpMessages()) std::this_thread::yield();
    const double t1 = rt.now();
    pe.recordWait(t1 - t0);
    t0 = t1;
  }
}

template <class Reply>
Reply awaitReply(Pe& pe, Channel<Reply>& replies, ChannelBase& serving, const std::string& what) {
  Reply reply;
  waitUntil(pe, serving, what, [&] { return replies.tryReceive(pe, reply); });
  return reply;
}

}  // namespace pr::par
