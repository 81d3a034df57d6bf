// Pe: a processing element as its code sees it while running a task or a message handler —
// its id, the stage it is in, and its live counters. The Runtime creates one per PE thread and
// per stage and passes it to every task and handler; Channel and DataManager count through it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

namespace pr::par {

class Runtime;

// Live counters of one PE in the running stage. Atomic (relaxed) because a sender counts the
// receiver's "received" figures and a data owner's "sent" ones; plain doubles are written only
// by the PE's own thread. Padded to a cache line so PEs do not false-share.
struct alignas(64) PeCounters {
  std::atomic<std::uint64_t> tasks{0}, messagesHandled{0};
  std::atomic<std::uint64_t> messagesSent{0}, bytesSent{0}, messagesReceived{0}, bytesReceived{0};
  std::atomic<std::uint64_t> schedulingMessages{0}, schedulingBytes{0};
  std::atomic<std::uint64_t> schedulingMessagesBetweenRanks{0}, schedulingBytesBetweenRanks{0};
  std::atomic<std::uint64_t> cacheHits{0}, cacheMisses{0}, prefetches{0};
  double busySeconds = 0.0;
  double sendReceiveSeconds = 0.0;  // inside Channel send, receive and broadcast calls
  double messageWaitSeconds = 0.0;  // waiting for a message: mailbox empty, work still to come
  double inTaskWaitSeconds = 0.0;   // the part of messageWaitSeconds spent inside a task
  double pendingWaitSeconds = 0.0;  // last wait between pieces of work, not yet known to be for a message
  double lastWorkEnd = 0.0;
};

class Pe {
 public:
  Pe(Runtime& runtime, int id, int pes, int stage, const std::string& stageName, PeCounters& counters)
      : runtime_(&runtime), id_(id), pes_(pes), stage_(stage), stageName_(&stageName), counters_(&counters) {}

  int id() const { return id_; }
  int pes() const { return pes_; }
  int stage() const { return stage_; }  // index into RunRecord::stages
  const std::string& stageName() const { return *stageName_; }
  Runtime& runtime() const { return *runtime_; }
  PeCounters& counters() const { return *counters_; }

  // A task that waits inside itself for another PE's message (a reply it asked for) books the
  // wait here: it is communication waiting, not busy time (the runtime subtracts it from the
  // task's span when it books busy).
  void recordWait(double seconds) const {
    counters_->messageWaitSeconds += seconds;
    counters_->inTaskWaitSeconds += seconds;
  }
  // Time inside a Channel call (send, receive), part of the task's busy time.
  void recordSendReceive(double seconds) const { counters_->sendReceiveSeconds += seconds; }

 private:
  Runtime* runtime_;
  int id_, pes_, stage_;
  const std::string* stageName_;
  PeCounters* counters_;
};

// Measures one Channel call for the PE that makes it (a scope guard).
class SendReceiveTimer {
 public:
  explicit SendReceiveTimer(const Pe& pe) : pe_(pe), t0_(std::chrono::steady_clock::now()) {}
  ~SendReceiveTimer() {
    pe_.recordSendReceive(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count());
  }
  SendReceiveTimer(const SendReceiveTimer&) = delete;
  SendReceiveTimer& operator=(const SendReceiveTimer&) = delete;

 private:
  const Pe& pe_;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace pr::par
