#include "common/util/interrupt.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
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
  std::atomic<bool> folder{false};
  char path[4096] = {};
};
static_assert(std::atomic<unsigned>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the handler needs lock-free atomics");
Slot gSlots[kMaxTemporaries];

// Removes what folder `dir` (open) holds, and the folders in it down to `depth` more levels,
// then closes it. Async-signal-safe: raw getdents64, openat, unlinkat, lseek, close, and a
// buffer on the stack; reading again from the start after each batch, since removing entries
// while reading on may skip some.
void removeContents(int dir, int depth) {
  struct Entry {
    unsigned long long ino;
    long long off;
    unsigned short reclen;
    unsigned char type;
    char name[1];
  };
  alignas(8) char buffer[2048];
  for (;;) {
    ::lseek(dir, 0, SEEK_SET);
    const long n = ::syscall(SYS_getdents64, dir, buffer, sizeof buffer);
    if (n <= 0) break;
    bool removed = false;
    for (long at = 0; at < n;) {
      const Entry* e = reinterpret_cast<const Entry*>(buffer + at);
      at += e->reclen;
      if (e->name[0] == '.' && (e->name[1] == '\0' || (e->name[1] == '.' && e->name[2] == '\0'))) continue;
      if (e->type == DT_DIR) {
        if (depth > 0) {
          const int sub = ::openat(dir, e->name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
          if (sub >= 0) removeContents(sub, depth - 1);
        }
        removed |= ::unlinkat(dir, e->name, AT_REMOVEDIR) == 0;
      } else {
        removed |= ::unlinkat(dir, e->name, 0) == 0;
      }
    }
    if (!removed) break;  // only what cannot be removed is left
  }
  ::close(dir);
}

// Async-signal-safe only: atomics, memcpy, unlink, the system calls above, write, _exit.
extern "C" void onInterrupt(int signal) {
  char copy[sizeof gSlots[0].path];
  for (Slot& slot : gSlots) {
    const unsigned before = slot.generation.load(std::memory_order_acquire);
    if ((before & 1u) || !slot.used.load(std::memory_order_acquire)) continue;
    std::memcpy(copy, slot.path, sizeof copy);
    const bool folder = slot.folder.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (slot.generation.load(std::memory_order_relaxed) != before) continue;
    copy[sizeof copy - 1] = '\0';
    if (folder) {
      const int dir = ::open(copy, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
      if (dir >= 0) removeContents(dir, kMaxFolderDepth);
      ::rmdir(copy);
    } else {
      ::unlink(copy);
    }
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

namespace {

int claimSlot(const char* path, bool folder) {
  const size_t length = std::strlen(path);
  if (length >= sizeof gSlots[0].path) return -1;
  for (int i = 0; i < kMaxTemporaries; ++i) {
    bool expected = false;
    if (!gSlots[i].claimed.compare_exchange_strong(expected, true)) continue;
    Slot& slot = gSlots[i];
    slot.generation.fetch_add(1, std::memory_order_acq_rel);  // odd: writing
    std::memcpy(slot.path, path, length + 1);
    slot.folder.store(folder, std::memory_order_relaxed);
    slot.generation.fetch_add(1, std::memory_order_release);  // even: complete
    slot.used.store(true, std::memory_order_release);
    return i;
  }
  return -1;
}

}  // namespace

int registerTemporary(const char* path) { return claimSlot(path, false); }

int registerTemporaryFolder(const char* path) { return claimSlot(path, true); }

void unregisterTemporary(int slot) {
  if (slot < 0 || slot >= kMaxTemporaries) return;
  gSlots[slot].used.store(false, std::memory_order_release);
  gSlots[slot].claimed.store(false, std::memory_order_release);
}

}  // namespace pr
