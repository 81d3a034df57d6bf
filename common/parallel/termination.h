// Termination detection for message-driven phases (work that creates messages that create
// work: rays, photons). One counter of outstanding work: the stage's tasks and PE set-ups not
// yet finished plus messages sent to a handled Channel and not yet handled. The runtime ends the phase when
// it reaches zero.
//
// Why this is correct under any interleaving:
//  - a task or set-up is counted from the start of the stage; a message is counted by its sender
//    *before* it is enqueued (add happens-before the receiver can pop it);
//  - the count is decremented only *after* the task, set-up or handler has returned, i.e. after
//    every message it sent has already been added;
//  - so at every instant count >= (queued messages + running tasks, set-ups and handlers +
//    tasks and set-ups not yet started), each term >= 0. count == 0 therefore means no work
//    exists anywhere, and since only tasks, set-ups and handlers create messages, none can
//    appear later: zero is final (stable).
//  - the decrement that reaches zero is acq_rel, so the PE that observes it also observes
//    every effect of the work counted before it.
#pragma once

#include <atomic>
#include <cstdint>

namespace pr::par {

class OutstandingWork {
 public:
  void reset(std::int64_t count) { count_.store(count, std::memory_order_release); }
  // Before the work becomes visible to another PE (before the enqueue).
  void add(std::int64_t n = 1) { count_.fetch_add(n, std::memory_order_relaxed); }
  // After the work and everything it sent are done; true for the call that reached zero.
  bool done(std::int64_t n = 1) { return count_.fetch_sub(n, std::memory_order_acq_rel) == n; }
  bool finished() const { return count_.load(std::memory_order_acquire) == 0; }
  std::int64_t count() const { return count_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::int64_t> count_{0};
};

}  // namespace pr::par
