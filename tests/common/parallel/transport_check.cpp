// parrender_transport_check: a program the process-group tests launch under mpirun to exercise
// the MPI transport and the group's bounded protocol with real processes.
//   exchange     every rank sends every other rank messages of 0 B to 1 MiB, each with a
//                pattern of its sender, size and destination; every rank checks what it got
//   fail RANK    rank RANK throws; the run ends on every rank with rank 0 naming it
//   hang RANK    rank RANK stops answering; rank 0's bounded wait ends every rank
// Exit status: the run's (finish), the same on every rank.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

#include "common/parallel/process_group.h"

namespace {

using pr::par::Bytes;
using pr::par::ProcessGroup;

constexpr int kTag = ProcessGroup::kFirstUserTag;
constexpr std::size_t kSizes[] = {0, 1, 1000, 1u << 20};

std::byte pattern(int from, int to, std::size_t size, std::size_t i) {
  return std::byte((std::size_t(from) * 131 + std::size_t(to) * 31 + size + i * 7) & 0xff);
}

void exchange(ProcessGroup& group) {
  const int me = group.rank(), ranks = group.ranks();
  for (int to = 0; to < ranks; ++to)
    if (to != me)
      for (std::size_t size : kSizes) {
        Bytes b(size);
        for (std::size_t i = 0; i < size; ++i) b[i] = pattern(me, to, size, i);
        group.transport().send(to, kTag, std::move(b));
      }
  const int expected = (ranks - 1) * int(std::size(kSizes));
  for (int got = 0; got < expected; ++got) {
    const pr::par::Envelope e = group.receive(kTag, "the exchange's messages");
    for (std::size_t i = 0; i < e.bytes.size(); ++i)
      if (e.bytes[i] != pattern(e.source, me, e.bytes.size(), i))
        throw std::runtime_error("byte " + std::to_string(i) + " of a " + std::to_string(e.bytes.size()) +
                                 "-byte message from rank " + std::to_string(e.source) + " differs");
  }
  if (me == 0) std::printf("exchange: %d ranks, %d messages each, all bytes as sent\n", ranks, expected);
}

}  // namespace

int main(int argc, char** argv) {
  ProcessGroup& group = ProcessGroup::start(&argc, &argv);
  const std::string mode = argc > 1 ? argv[1] : "exchange";
  const int target = argc > 2 ? std::atoi(argv[2]) : -1;
  int status = 0;
  std::string error;
  try {
    if (mode == "exchange") exchange(group);
    if (mode == "fail" && group.rank() == target) throw std::runtime_error("an injected failure");
    if (mode == "hang" && group.rank() == target) std::this_thread::sleep_for(std::chrono::seconds(60));
  } catch (const std::exception& e) {
    status = 1;
    error = e.what();
  }
  return group.finish(status, error);
}
