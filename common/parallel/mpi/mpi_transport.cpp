// The MPI transport module (see transport.h): point-to-point messages as nonblocking MPI sends
// (the bytes kept until MPI_Test says they have left) and matched probes (MPI_Improbe, safe
// when several threads receive), on a duplicate of MPI_COMM_WORLD. The only code that includes
// mpi.h; loaded by process_group.cpp when mpirun launched the program.
#include <mpi.h>
#include <sys/mman.h>

#include <cstdint>

#include <algorithm>
#include <bit>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstdio>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "common/parallel/transport.h"

namespace pr::par {
namespace {

// Whole 2 MiB pages inside a buffer about to be written once (common/util/allocator.h says
// why; repeated here, since this module links nothing of parrender's).
void adviseHugePages(const void* data, std::size_t bytes) {
  constexpr std::uintptr_t kHugePage = std::uintptr_t(2) << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHugePage - 1);
  if (data && last > first) (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
}

class MpiTransport final : public Transport {
 public:
  explicit MpiTransport(MPI_Comm comm) : comm_(comm) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &ranks_);
  }

  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }

  void send(int to, int tag, Bytes bytes) override {
    if (bytes.size() > std::size_t(INT_MAX)) throw std::runtime_error("a message of 2 GiB or more cannot be sent in one MPI call");
    std::lock_guard lock(mutex_);
    completeSends();
    Pending& p = pending_.emplace_back();
    p.bytes = std::move(bytes);
    if (MPI_Isend(p.bytes.data(), int(p.bytes.size()), MPI_BYTE, to, tag, comm_, &p.request) != MPI_SUCCESS)
      pending_.pop_back();  // only with tolerateLostRanks: the receiver is gone
  }

  std::optional<Envelope> poll(int tag) override {
    std::lock_guard lock(mutex_);
    completeSends();
    int found = 0;
    MPI_Message message;
    MPI_Status status;
    if (MPI_Improbe(MPI_ANY_SOURCE, tag, comm_, &found, &message, &status) != MPI_SUCCESS || !found) return std::nullopt;
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    Envelope e;
    e.source = status.MPI_SOURCE;
    e.tag = tag;
    e.bytes = takeSpare(std::size_t(count));
    e.bytes.resize(std::size_t(count));  // zero-fills only beyond what the storage held before
    if (MPI_Mrecv(e.bytes.data(), count, MPI_BYTE, &message, MPI_STATUS_IGNORE) != MPI_SUCCESS) return std::nullopt;
    return e;
  }

  Bytes storage(std::size_t bytes) override {
    std::lock_guard lock(mutex_);
    Bytes b = takeSpare(bytes);
    b.clear();
    return b;
  }

  void recycle(Bytes&& bytes) override {
    std::lock_guard lock(mutex_);
    keepSpare(std::move(bytes));
  }

  bool sending() override {
    std::lock_guard lock(mutex_);
    completeSends();
    return !pending_.empty();
  }

  // A large message moves in fragments, each only while this rank is inside MPI (no
  // asynchronous progress): test without sleeping for the first second, then every 200 us.
  bool flush(double seconds) override {
    const auto start = std::chrono::steady_clock::now();
    const auto deadline = start + std::chrono::duration<double>(seconds);
    for (;;) {
      {
        std::lock_guard lock(mutex_);
        completeSends();
        if (pending_.empty()) return true;
      }
      const auto now = std::chrono::steady_clock::now();
      if (now > deadline) return false;
      if (now - start < std::chrono::seconds(1))
        std::this_thread::yield();
      else
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }

  // MPI_ERRORS_RETURN instead of the default fatal handler: every call above checks its code.
  void tolerateLostRanks() override { MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN); }

  void finalize() override {
    MPI_Comm_free(&comm_);
    MPI_Finalize();
  }

  [[noreturn]] void abortAll(int status) override {
    MPI_Abort(comm_, status);
    std::_Exit(status);  // MPI_Abort does not return; should it, the rank still ends
  }

 private:
  struct Pending {
    Bytes bytes;
    MPI_Request request = MPI_REQUEST_NULL;
  };

  // With mutex_ held: drops the sends MPI has finished with, oldest first.
  void completeSends() {
    while (!pending_.empty()) {
      int done = 0;
      // A failed test (tolerateLostRanks: the receiver is gone) drops the send.
      if (MPI_Test(&pending_.front().request, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && !done) return;
      keepSpare(std::move(pending_.front().bytes));
      pending_.pop_front();
    }
  }

  // With mutex_ held: for a message of kSmallestSpare bytes or more, the smallest spare with
  // room for it and at most twice what new storage would get (a probe never takes a frame's
  // strip); else new storage, whose whole 2 MiB pages are backed by 2 MiB pages when it is
  // large (a fresh 4 KiB page costs about 12 us on the 2-core development machine), with room
  // to spare: a message a little larger than the last (a frame's region as the view moves)
  // then fits what was kept; pages beyond what is written are never touched.
  Bytes takeSpare(std::size_t bytes) {
    if (bytes >= kSmallestSpare) {
      const std::size_t most = 2 * std::bit_ceil(bytes);
      auto best = spare_.end();
      for (auto it = spare_.begin(); it != spare_.end(); ++it)
        if (it->capacity() >= bytes && it->capacity() <= most && (best == spare_.end() || it->capacity() < best->capacity()))
          best = it;
      if (best != spare_.end()) {
        Bytes b = std::move(*best);
        spare_.erase(best);
        return b;
      }
    }
    Bytes b;
    b.reserve(bytes < kSmallestSpare ? bytes : std::bit_ceil(bytes));
    adviseHugePages(b.data(), b.capacity());
    return b;
  }

  // With mutex_ held: keeps storage for later messages, at most kSpares, the oldest leaving
  // first. Not what is larger than kLargestSpare: such a message is a one-off (a first
  // frame's geometry share), not one every frame.
  void keepSpare(Bytes&& bytes) {
    if (bytes.capacity() < kSmallestSpare || bytes.capacity() > kLargestSpare) return;
    spare_.push_back(std::move(bytes));
    if (spare_.size() > kSpares) spare_.erase(spare_.begin());
  }

  static constexpr std::size_t kSpares = 8;
  static constexpr std::size_t kSmallestSpare = std::size_t(64) << 10;  // smaller blocks are cheap to allocate
  static constexpr std::size_t kLargestSpare = std::size_t(32) << 20;

  MPI_Comm comm_;
  int rank_ = 0, ranks_ = 1;
  std::mutex mutex_;
  std::deque<Pending> pending_;  // a deque: buffers never move while MPI reads them
  std::vector<Bytes> spare_;     // storage of sends that have left and of messages read
};

}  // namespace
}  // namespace pr::par

extern "C" pr::par::Transport* parrender_mpi_transport(int* argc, char*** argv, char* error, int errorSize) {
  int provided = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_MULTIPLE, &provided) != MPI_SUCCESS) {
    std::snprintf(error, std::size_t(errorSize), "MPI_Init_thread failed");
    return nullptr;
  }
  if (provided < MPI_THREAD_MULTIPLE) {
    std::snprintf(error, std::size_t(errorSize), "this MPI library gives thread level %d, not MPI_THREAD_MULTIPLE", provided);
    MPI_Finalize();
    return nullptr;
  }
  MPI_Comm comm;
  MPI_Comm_dup(MPI_COMM_WORLD, &comm);
  return new pr::par::MpiTransport(comm);
}
