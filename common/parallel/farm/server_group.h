// The farm's servers as a group of their own (farm.h): a Transport over ranks 1..S of the run,
// renumbered 0..S-1, on tags of their own, so that a Runtime across processes (runtime.h) can
// run SPMD stages among the servers alone - the farm's shared pre-passes, each server tracing
// its share of the photons and the maps all-gathered - while the master, rank 0, takes no part.
#pragma once

#include <cstdlib>
#include <optional>

#include "common/parallel/transport.h"

namespace pr::par {

class ServerGroupTransport final : public Transport {
 public:
  // Tags of the group: the runtime's own tags moved up by this much (MPI guarantees tags up
  // to 32767; the runtime's and the farm's are below 3100, farm_messages.h).
  static constexpr int kTagOffset = 10000;

  explicit ServerGroupTransport(Transport& run) : run_(run) {}
  int rank() const override { return run_.rank() - 1; }
  int ranks() const override { return run_.ranks() - 1; }
  void send(int to, int tag, Bytes bytes) override { run_.send(to + 1, tag + kTagOffset, std::move(bytes)); }
  std::optional<Envelope> poll(int tag) override {
    std::optional<Envelope> e = run_.poll(tag + kTagOffset);
    if (e) {
      e->source -= 1;
      e->tag = tag;
    }
    return e;
  }
  Bytes storage(std::size_t bytes) override { return run_.storage(bytes); }
  void recycle(Bytes&& bytes) override { run_.recycle(std::move(bytes)); }
  bool flush(double seconds) override { return run_.flush(seconds); }
  bool sending() override { return run_.sending(); }
  void finalize() override {}  // the run's transport ends with the run
  [[noreturn]] void abortAll(int status) override {
    run_.abortAll(status);
    std::_Exit(status);  // abortAll does not return; the compiler cannot see that through the virtual call
  }

 private:
  Transport& run_;
};

}  // namespace pr::par
