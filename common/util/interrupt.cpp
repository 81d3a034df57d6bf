#include "common/util/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

namespace pr {

namespace {

// A slot is a seqlock: its generation is odd while the owner writes the path, so the handler,
// which may run while another thread re-registers the slot, copies the path and unlinks the
// copy only when the generation was even and unchanged around the copy (no torn path).
struct Slot {
  std::atomic<bool> claimed{false};
  std::atomic<unsigned> generation{0};
  std::atomic<bool> used{false};
  char path[4096] = {};
};
static_assert(std::atomic<unsigned>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the handler needs lock-free atomics");
Slot gSlots[kMaxTemporaries];

// Async-signal-safe only: atomics, memcpy, unlink, write, _exit.
extern "C" void onInterrupt(int signal) {
  char copy[sizeof gSlots[0].path];
  for (Slot& slot : gSlots) {
    const unsigned before = slot.generation.load(std::memory_order_acquire);
    if ((before & 1u) || !slot.used.load(std::memory_order_acquire)) continue;
    std::memcpy(copy, slot.path, sizeof copy);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (slot.generation.load(std::memory_order_relaxed) != before) continue;
    copy[sizeof copy - 1] = '\0';
    ::unlink(copy);
  }
  static const char kMessage[] = "\nparrender: interrupted; outputs in progress removed\n";
  ssize_t ignored = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  (void)ignored;
  ::_exit(128 + signal);
}

}  // namespace

void installInterruptHandler() {
  for (int signal : {SIGINT, SIGTERM}) {
    struct sigaction previous {};
    sigaction(signal, nullptr, &previous);
    if (previous.sa_handler == SIG_IGN) continue;  // e.g. nohup or a shell's background job: keep ignoring
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    sigaction(signal, &action, nullptr);
  }
}

int registerTemporary(const char* path) {
  const size_t length = std::strlen(path);
  if (length >= sizeof gSlots[0].path) return -1;
  for (int i = 0; i < kMaxTemporaries; ++i) {
    bool expected = false;
    if (!gSlots[i].claimed.compare_exchange_strong(expected, true)) continue;
    Slot& slot = gSlots[i];
    slot.generation.fetch_add(1, std::memory_order_acq_rel);  // odd: writing
    std::memcpy(slot.path, path, length + 1);
    slot.generation.fetch_add(1, std::memory_order_release);  // even: complete
    slot.used.store(true, std::memory_order_release);
    return i;
  }
  return -1;
}

void unregisterTemporary(int slot) {
  if (slot < 0 || slot >= kMaxTemporaries) return;
  gSlots[slot].used.store(false, std::memory_order_release);
  gSlots[slot].claimed.store(false, std::memory_order_release);
}

}  // namespace pr
