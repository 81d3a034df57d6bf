// bench_transport: the MPI transport (common/parallel/transport.h, opened by the process group)
// against a plain MPI ping-pong of the same sizes between the same two ranks, in the same run:
// round-trip time and bandwidth per message size, and their ratio. Run under mpirun:
//   mpirun -np 2 build/tools/bench/bench_transport [--rounds N]
// (as root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). Rank 0 sends, rank 1
// echoes; each size runs the plain ping-pong and the transport's in turns, best of 3.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "common/parallel/process_group.h"

namespace {

using pr::par::Bytes;
using pr::par::ProcessGroup;
using Clock = std::chrono::steady_clock;

constexpr int kTag = ProcessGroup::kFirstUserTag;

// Seconds per round trip of `rounds` plain MPI_Send / MPI_Recv pairs.
double plainPingPong(std::size_t size, int rounds, int rank) {
  std::vector<char> buffer(std::max<std::size_t>(size, 1));
  MPI_Barrier(MPI_COMM_WORLD);
  const auto t0 = Clock::now();
  for (int i = 0; i < rounds; ++i) {
    if (rank == 0) {
      MPI_Send(buffer.data(), int(size), MPI_BYTE, 1, 7, MPI_COMM_WORLD);
      MPI_Recv(buffer.data(), int(size), MPI_BYTE, 1, 7, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    } else {
      MPI_Recv(buffer.data(), int(size), MPI_BYTE, 0, 7, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      MPI_Send(buffer.data(), int(size), MPI_BYTE, 0, 7, MPI_COMM_WORLD);
    }
  }
  return std::chrono::duration<double>(Clock::now() - t0).count() / rounds;
}

// The same through the transport: send, and poll until the echo arrives.
double transportPingPong(ProcessGroup& group, std::size_t size, int rounds) {
  MPI_Barrier(MPI_COMM_WORLD);
  const int other = 1 - group.rank();
  const auto t0 = Clock::now();
  for (int i = 0; i < rounds; ++i) {
    if (group.rank() == 0) {
      group.transport().send(other, kTag, Bytes(size));
      (void)group.receive(kTag, "the echo");
    } else {
      pr::par::Envelope e = group.receive(kTag, "the ping");
      group.transport().send(other, kTag, std::move(e.bytes));
    }
  }
  return std::chrono::duration<double>(Clock::now() - t0).count() / rounds;
}

}  // namespace

int main(int argc, char** argv) {
  ProcessGroup& group = ProcessGroup::start(&argc, &argv);
  int rounds = 2000;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--rounds") rounds = std::max(1, std::atoi(argv[i + 1]));
  if (group.ranks() != 2) {
    std::fprintf(stderr, "bench_transport: run it as 2 ranks (mpirun -np 2), not %d\n", group.ranks());
    return group.ranks() == 1 ? 2 : group.finish(2, "");
  }
  if (group.rank() == 0)
    std::printf("%10s %14s %14s %12s %12s %7s\n", "bytes", "plain_rt_us", "transport_us", "plain_MB/s", "transp_MB/s",
                "ratio");
  for (std::size_t size : {std::size_t(8), std::size_t(1024), std::size_t(64 * 1024), std::size_t(1024 * 1024)}) {
    const int n = size >= 64 * 1024 ? std::max(1, rounds / 10) : rounds;
    double plain = 1e30, transport = 1e30;
    for (int turn = 0; turn < 3; ++turn) {
      plain = std::min(plain, plainPingPong(size, n, group.rank()));
      transport = std::min(transport, transportPingPong(group, size, n));
    }
    if (group.rank() == 0)
      std::printf("%10zu %14.2f %14.2f %12.1f %12.1f %7.2f\n", size, plain * 1e6, transport * 1e6,
                  2.0 * double(size) / plain * 1e-6, 2.0 * double(size) / transport * 1e-6, transport / plain);
  }
  return group.finish(0, "");
}
