// parrender_transport_check: a program the process-group tests launch under mpirun to exercise
// the MPI transport and the group's bounded protocol with real processes.
//   exchange     every rank sends every other rank messages of 0 B to 1 MiB, each with a
//                pattern of its sender, size and destination; every rank checks what it got
//   fail RANK    rank RANK throws; the run ends on every rank with rank 0 naming it
//   hang RANK    rank RANK stops answering; rank 0's bounded wait ends every rank
//   stages T     the runtime on T PEs per rank: under several strategies, every task runs once
//                and chains of messages that cross ranks end before their stage does
//   stagefail PE a task on PE PE throws; the stage ends on every rank, rank 0 reports it
//   alone S      rank 0 works alone for S seconds (past PARRENDER_RANK_TIMEOUT) while the others
//                wait; every rank gets its result
//   alonefail    rank 0's work alone throws; every rank ends, rank 0 reports it
// Exit status: the run's (finish), the same on every rank.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "common/parallel/channel.h"
#include "common/parallel/process_group.h"
#include "common/parallel/runtime.h"

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

struct Hop {
  std::int32_t left, chain;
};

// Each rank's figures go to rank 0, which checks their sums: every task once, every hop once.
void stages(ProcessGroup& group, int threads) {
  constexpr int kTasks = 200, kChains = 16, kLength = 30;
  for (const char* schedule : {"demand", "balanced", "distributed", "task-manager"}) {
    pr::par::Runtime rt(pr::par::RuntimeOptions{group.ranks() * threads, schedule, {}, true, &group.transport()});
    long taskSum = 0, tasks = 0;
    std::atomic<long> hopsHandled{0};
    pr::par::Channel<Hop> hops(rt, "hops", pr::par::MessageKind::Rays, [&](pr::par::Pe& pe, Hop&& h) {
      ++hopsHandled;
      if (h.left > 0) hops.send(pe, (pe.id() + 1 + h.chain) % rt.pes(), Hop{h.left - 1, h.chain});
    });
    std::mutex mutex;
    rt.runStage("tasks", pr::par::TaskSet::uniform(kTasks), [&](pr::par::Pe&, pr::par::TaskId t) {
      std::lock_guard lock(mutex);
      taskSum += t;
      ++tasks;
    });
    rt.runStage("chains", pr::par::TaskSet::uniform(kChains), [&](pr::par::Pe& pe, pr::par::TaskId t) {
      hops.send(pe, (pe.id() + 1) % rt.pes(), Hop{kLength, static_cast<std::int32_t>(t)});
    });
    const long mine[3] = {tasks, taskSum, hopsHandled.load()};
    if (group.rank() != 0) {
      Bytes b(sizeof mine);
      std::memcpy(b.data(), mine, sizeof mine);
      group.transport().send(0, kTag, std::move(b));
      continue;
    }
    long sum[3] = {mine[0], mine[1], mine[2]};
    for (int r = 1; r < group.ranks(); ++r) {
      const pr::par::Envelope e = group.receive(kTag, "a rank's figures");
      long theirs[3];
      std::memcpy(theirs, e.bytes.data(), sizeof theirs);
      for (int i = 0; i < 3; ++i) sum[i] += theirs[i];
    }
    if (sum[0] != kTasks || sum[1] != long(kTasks) * (kTasks - 1) / 2 || sum[2] != long(kChains) * (kLength + 1))
      throw std::runtime_error(std::string(schedule) + ": " + std::to_string(sum[0]) + " tasks, id sum " +
                               std::to_string(sum[1]) + ", " + std::to_string(sum[2]) + " hops");
    std::printf("stages: %s on %d ranks x %d PEs: %d tasks once each, %d hops\n", schedule, group.ranks(), threads,
                kTasks, kChains * (kLength + 1));
  }
}

void stageFail(ProcessGroup& group, int failingPe) {
  pr::par::Runtime rt(pr::par::RuntimeOptions{group.ranks() * 2, "demand", {}, true, &group.transport()});
  rt.runStage("breaks", pr::par::TaskSet::uniform(64), [&](pr::par::Pe& pe, pr::par::TaskId) {
    if (pe.id() == failingPe) throw std::runtime_error("an injected task failure");
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  });
}

// Rank 0 works alone for `seconds`, then gives every rank a result naming its size.
void alone(ProcessGroup& group, int seconds, bool fail) {
  const std::string made = "made on rank 0 alone";
  const Bytes result = group.onRank0Alone("the test's work on rank 0", [&] {
    std::this_thread::sleep_for(std::chrono::seconds(seconds));
    if (fail) throw std::runtime_error("an injected failure alone");
    return Bytes(reinterpret_cast<const std::byte*>(made.data()), reinterpret_cast<const std::byte*>(made.data()) + made.size());
  });
  if (std::string(reinterpret_cast<const char*>(result.data()), result.size()) != made)
    throw std::runtime_error("rank " + std::to_string(group.rank()) + " got another result");
  std::printf("alone: rank %d got rank 0's result\n", group.rank());
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
    if (mode == "stages") stages(group, target);
    if (mode == "stagefail") stageFail(group, target);
    if (mode == "alone" || mode == "alonefail") alone(group, std::max(0, target), mode == "alonefail");
    if (mode == "fail" && group.rank() == target) throw std::runtime_error("an injected failure");
    if (mode == "hang" && group.rank() == target) std::this_thread::sleep_for(std::chrono::seconds(60));
  } catch (const pr::par::FailedElsewhere&) {
    status = 1;  // the rank where it failed reports it
  } catch (const std::exception& e) {
    status = 1;
    error = e.what();
  }
  return group.finish(status, error);
}
