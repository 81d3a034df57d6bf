// Transport: moves the bytes of messages between the ranks (processes) of one run, under the
// runtime (shared/DESIGN.md, "Transports"). PEs of one rank exchange messages in shared memory;
// only what leaves a rank becomes bytes on a Transport. The MPI transport is a module of its
// own (common/parallel/mpi/mpi_transport.cpp), opened only when mpirun launched the program,
// so a process started without mpirun never initialises MPI. Every wait on a transport is
// bounded (process_group.h).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace pr::par {

using Bytes = std::vector<std::byte>;

// A message as it arrives: who sent it, its tag and its bytes.
struct Envelope {
  int source = -1;
  int tag = 0;
  Bytes bytes;
};

class Transport {
 public:
  virtual ~Transport() = default;
  virtual int rank() const = 0;
  virtual int ranks() const = 0;
  // Sends `bytes` to rank `to` under `tag` and returns at once; the transport keeps the bytes
  // until they have left. Callable from any thread.
  virtual void send(int to, int tag, Bytes bytes) = 0;
  // A message with `tag` from any rank, if one has arrived; never blocks. Any thread.
  virtual std::optional<Envelope> poll(int tag) = 0;
  // Storage for a message about to be sent: empty, with room for `bytes`. A transport may hand
  // out the storage of sends that have left and of received messages given back (recycle), so
  // that a large message every frame is not a fresh allocation faulted in page by page (on the
  // 2-core development machine a fresh 2.6 MB receive buffer took 7 ms). Any thread.
  virtual Bytes storage(std::size_t bytes) {
    Bytes b;
    b.reserve(bytes);
    return b;
  }
  // Gives a received message's bytes back, once read, for later messages. Any thread.
  virtual void recycle(Bytes&& bytes) { (void)bytes; }
  // Waits (bounded by `seconds`) for every send to have left; false if some had not.
  virtual bool flush(double seconds) = 0;
  // Whether a send has not left yet (it moves only while some thread of this rank calls the
  // transport, without asynchronous progress). Any thread.
  virtual bool sending() { return false; }
  // From now on a rank that died or stopped does not end this one: a send to it, or a receive
  // its death disturbs, fails quietly (its message is dropped), and the caller's deadlines say
  // when it is lost (the farm, farm/farm.h). Needs `mpirun --enable-recovery` under MPI.
  virtual void tolerateLostRanks() {}
  // Ends the transport on this rank (after flush); the last call made on it.
  virtual void finalize() = 0;
  // Ends every rank of the run at once with `status` (a rank that cannot finish cleanly).
  [[noreturn]] virtual void abortAll(int status) = 0;
};

}  // namespace pr::par

// The MPI module's one entry point (C linkage, found by dlsym): initialises MPI (thread level
// MPI_THREAD_MULTIPLE) and returns the transport over MPI_COMM_WORLD, or nullptr with a reason
// in `error` (a buffer of errorSize bytes).
extern "C" pr::par::Transport* parrender_mpi_transport(int* argc, char*** argv, char* error, int errorSize);
