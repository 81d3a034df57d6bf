#include "common/util/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

namespace pr {

namespace {

// Written by the owning thread before `used` is set (release), read by the handler after it
// sees `used` (acquire): a slot is complete whenever the handler can see it.
struct Slot {
  std::atomic<bool> used{false};
  char path[4096] = {};
};
Slot gSlots[kMaxTemporaries];
std::atomic<bool> gClaim[kMaxTemporaries];

// Async-signal-safe only: unlink, write, _exit.
extern "C" void onInterrupt(int signal) {
  for (Slot& slot : gSlots)
    if (slot.used.load(std::memory_order_acquire)) ::unlink(slot.path);
  static const char kMessage[] = "\nparrender: interrupted; no output written\n";
  ssize_t ignored = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  (void)ignored;
  ::_exit(128 + signal);
}

}  // namespace

void installInterruptHandler() {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int registerTemporary(const char* path) {
  const size_t length = std::strlen(path);
  if (length >= sizeof gSlots[0].path) return -1;
  for (int i = 0; i < kMaxTemporaries; ++i) {
    bool expected = false;
    if (!gClaim[i].compare_exchange_strong(expected, true)) continue;
    std::memcpy(gSlots[i].path, path, length + 1);
    gSlots[i].used.store(true, std::memory_order_release);
    return i;
  }
  return -1;
}

void unregisterTemporary(int slot) {
  if (slot < 0 || slot >= kMaxTemporaries) return;
  gSlots[slot].used.store(false, std::memory_order_release);
  gClaim[slot].store(false);
}

}  // namespace pr
