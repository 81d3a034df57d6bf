// Waiting inside a task for a reply from another PE (a tile's bins, a data item): the PE keeps
// serving the messages of every handled channel sent to it meanwhile (Runtime::serveOne), so
// PEs waiting on each other always make progress, whichever channels they wait on, and books
// the time it spent with nothing to do as message waiting, not busy (Pe::recordWait). Used by
// TilePull (raster dynamic regions) and DataManager.
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>
#include <thread>

#include "common/parallel/channel.h"

namespace pr::par {

// On PE pe inside a task: polls done() until it returns true, answering the messages of every
// handled channel meanwhile. A turn that neither finished nor answered a message is booked as
// waiting (Pe::recordWait), less the time its poll spent in Channel calls, which the channel
// already booked as send/receive time; answering is busy. When another PE fails, the stage
// aborts and what it waits for may never come: throws std::runtime_error naming `what` instead
// of waiting forever (the runtime keeps the first error, so the original failure is what
// runStage rethrows).
template <class Done>
void waitUntil(Pe& pe, const std::string& what, Done&& done) {
  Runtime& rt = pe.runtime();
  double t0 = rt.now();
  double polled0 = pe.counters().sendReceiveSeconds;
  while (!done()) {
    if (rt.aborting()) throw std::runtime_error("stage aborted while PE " + std::to_string(pe.id()) + " waited for " + what);
    if (rt.serveOne(pe)) {
      t0 = rt.now();
      polled0 = pe.counters().sendReceiveSeconds;
      continue;
    }
    // Across ranks a reply from another rank arrives only while some thread of this one calls
    // the transport: this PE does, rather than wait for the controlling thread's next poll.
    if (!rt.pumpMessages()) std::this_thread::yield();
    const double t1 = rt.now();
    const double polled = pe.counters().sendReceiveSeconds;
    pe.recordWait(std::max(0.0, (t1 - t0) - (polled - polled0)));
    t0 = t1;
    polled0 = polled;
  }
}

// On PE pe inside a task: the next message of `replies` for pe, serving as waitUntil does.
template <class Reply>
Reply awaitReply(Pe& pe, Channel<Reply>& replies, const std::string& what) {
  Reply reply;
  waitUntil(pe, what, [&] { return replies.tryReceive(pe, reply); });
  return reply;
}

}  // namespace pr::par
