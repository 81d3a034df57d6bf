// See process_group.h.
#include "common/parallel/process_group.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "common/parallel/runtime.h"
#include "common/util/error.h"
#include "common/util/hash.h"
#include "common/util/module_loader.h"

namespace pr::par {
namespace {

std::unique_ptr<ProcessGroup> group;

// The verdict's text when a rank was lost: the others leave without MPI_Finalize.
constexpr const char* kLeaveWithoutFinalize = "leave without finalize";

// A status message: the exit status (4 bytes) and the failure's text.
Bytes encodeStatus(int status, const std::string& text) {
  Bytes b(sizeof(std::int32_t) + text.size());
  const std::int32_t s = status;
  std::memcpy(b.data(), &s, sizeof s);
  std::memcpy(b.data() + sizeof s, text.data(), text.size());
  return b;
}

int decodeStatus(const Bytes& b, std::string& text) {
  std::int32_t s = 1;
  if (b.size() >= sizeof s) std::memcpy(&s, b.data(), sizeof s);
  text.assign(reinterpret_cast<const char*>(b.data()) + std::min(b.size(), sizeof s), b.size() - std::min(b.size(), sizeof s));
  return s;
}

// FNV-1a over the arguments after the program name, each ended by a zero byte.
std::uint64_t commandLineHash(int argc, char** argv) {
  Fnv1a h;
  for (int i = 1; i < argc; ++i) h.bytes(argv[i], std::strlen(argv[i]) + 1);
  return h.value();
}

}  // namespace

int launchedRanks() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  return size ? std::max(1, std::atoi(size)) : 1;
}

int launchedRank() {
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  return rank ? std::max(0, std::atoi(rank)) : 0;
}

void printFailure(int status, int rank, int ranks, const std::string& text) {
  const char* kind = status == kExitBadInput ? "error" : "failed";
  if (ranks == 1)
    std::fprintf(stderr, "parrender: %s: %s\n", kind, text.c_str());
  else
    std::fprintf(stderr, "parrender: %s (rank %d of %d): %s\n", kind, rank, ranks, text.c_str());
}

ProcessGroup& ProcessGroup::start(int* argc, char*** argv) {
  PR_CHECK(!group, "ProcessGroup::start is called once");
  group.reset(new ProcessGroup());
  // One rank (no mpirun, or mpirun -np 1): today's single process, MPI never initialised.
  if (launchedRanks() <= 1) return *group;
  if (const char* t = std::getenv("PARRENDER_RANK_TIMEOUT"); t && *t) {
    char* end = nullptr;
    const double seconds = std::strtod(t, &end);
    if (end == t || *end || !(seconds > 0.0)) throw InputError("PARRENDER_RANK_TIMEOUT must be a positive number of seconds");
    group->timeout_ = seconds;
  }
  using Entry = Transport* (*)(int*, char***, char*, int);
  const auto entry = reinterpret_cast<Entry>(openModuleEntry("libparrender_mpi.so", "PARRENDER_MPI_MODULE", "parrender_mpi_transport"));
  char error[256] = {};
  group->transport_ = entry(argc, argv, error, int(sizeof error));
  if (!group->transport_) throw std::runtime_error(std::string("cannot start MPI: ") + error);
  group->rank_ = group->transport_->rank();
  group->ranks_ = group->transport_->ranks();
  return *group;
}

ProcessGroup& ProcessGroup::get() {
  PR_CHECK(group != nullptr, "ProcessGroup::start has not been called");
  return *group;
}

Transport& ProcessGroup::transport() {
  PR_CHECK(transport_ != nullptr, "a group of one rank has no transport");
  return *transport_;
}

Envelope ProcessGroup::receive(int tag, std::string_view what) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_);
  // Poll, yielding the core, for the first few thousand tries (a reply usually comes within
  // microseconds), then sleep between polls, so a rank that waits long costs its core nothing.
  for (int tries = 0;; ++tries) {
    if (std::optional<Envelope> e = transport().poll(tag)) return std::move(*e);
    if (tries < 4096) {
      std::this_thread::yield();
      continue;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      std::fprintf(stderr, "parrender: failed (rank %d of %d): no answer within %.0f s while waiting for %.*s; ending every rank\n",
                   rank_, ranks_, timeout_, int(what.size()), what.data());
      transport_->abortAll(1);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

void ProcessGroup::checkSameCommandLine(int argc, char** argv) {
  if (ranks_ == 1) return;
  const std::uint64_t mine = commandLineHash(argc, argv);
  Bytes hash(sizeof mine);
  std::memcpy(hash.data(), &mine, sizeof mine);
  if (rank_ != 0) {
    transport_->send(0, kCommandLineTag, std::move(hash));
    std::string text;
    if (decodeStatus(receive(kVerdictTag, "rank 0's check of the command line").bytes, text) != 0) throw InputError("");
    return;
  }
  int differs = -1;
  for (int got = 1; got < ranks_; ++got) {
    const Envelope e = receive(kCommandLineTag, "every rank's command line");
    std::uint64_t theirs = 0;
    if (e.bytes.size() == sizeof theirs) std::memcpy(&theirs, e.bytes.data(), sizeof theirs);
    if (theirs != mine && (differs < 0 || e.source < differs)) differs = e.source;
  }
  for (int r = 1; r < ranks_; ++r) transport_->send(r, kVerdictTag, encodeStatus(differs < 0 ? 0 : kExitBadInput, ""));
  if (differs >= 0)
    throw InputError("rank " + std::to_string(differs) +
                     " was started with a different command line from rank 0's: every rank must get the same options");
}

namespace {
// The first byte of a message under kAloneTag; a result follows kDone.
enum class AloneNews : std::uint8_t { kWorking = 0, kDone = 1, kFailed = 2 };

Bytes aloneMessage(AloneNews news, const Bytes& result = {}) {
  Bytes b(1 + result.size());
  b[0] = std::byte(news);
  std::copy(result.begin(), result.end(), b.begin() + 1);
  return b;
}
}  // namespace

Bytes ProcessGroup::onRank0Alone(std::string_view what, const std::function<Bytes()>& work) {
  if (ranks_ == 1) return work();
  if (rank_ != 0) {
    for (;;) {
      Envelope e = receive(kAloneTag, what);
      const AloneNews news = e.bytes.empty() ? AloneNews::kFailed : AloneNews(e.bytes[0]);
      if (news == AloneNews::kWorking) continue;
      if (news != AloneNews::kDone) throw FailedElsewhere("rank 0 failed while working alone on " + std::string(what));
      e.bytes.erase(e.bytes.begin());
      return std::move(e.bytes);
    }
  }
  // Rank 0: a thread sends "still working" well within the others' deadline until work ends.
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  const auto every = std::chrono::duration<double>(std::min(2.0, timeout_ / 4.0));
  std::thread heartbeat([&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (!finished.wait_for(lock, every, [&] { return done; }))
      for (int r = 1; r < ranks_; ++r) transport_->send(r, kAloneTag, aloneMessage(AloneNews::kWorking));
  });
  const auto stopHeartbeat = [&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
    }
    finished.notify_one();
    heartbeat.join();
  };
  Bytes result;
  try {
    result = work();
  } catch (...) {
    stopHeartbeat();
    for (int r = 1; r < ranks_; ++r) transport_->send(r, kAloneTag, aloneMessage(AloneNews::kFailed));
    throw;
  }
  stopHeartbeat();
  for (int r = 1; r < ranks_; ++r) transport_->send(r, kAloneTag, aloneMessage(AloneNews::kDone, result));
  return result;
}

int ProcessGroup::finish(int status, const std::string& error) {
  if (ranks_ == 1) {
    if (status != 0 && !error.empty()) printFailure(status, 0, 1, error);
    if (atVerdict_) atVerdict_(status);
    return status;
  }
  int run = status;
  if (rank_ != 0) {
    transport_->send(0, kStatusTag, encodeStatus(status, error));
    std::string ending;
    run = decodeStatus(receive(kFinishTag, "rank 0 to end the run").bytes, ending);
    // A rank was lost (markLost): MPI_Finalize could wait for it for ever, and rank 0 ends the
    // run by abortAll once every other rank has left, so this one leaves without MPI.
    if (ending == kLeaveWithoutFinalize) {
      (void)transport_->flush(timeout_);
      std::fflush(stdout);
      std::fflush(stderr);
      std::_Exit(run);
    }
  } else {
    // The failure to report, printed as soon as it is known (so a later rank that never
    // answers cannot hide it): rank 0's own, else the first to arrive.
    // A failure without text (one that another rank reports) waits for that rank's.
    bool reported = false;
    if (status != 0 && !error.empty()) {
      printFailure(status, 0, ranks_, error);
      reported = true;
    }
    const auto lost = [&](int r) { return r < int(lost_.size()) && lost_[std::size_t(r)]; };
    int live = 0;
    for (int r = 1; r < ranks_; ++r) live += lost(r) ? 0 : 1;
    for (int got = 0; got < live;) {
      const Envelope e = receive(kStatusTag, "every rank's status at the end of the run");
      if (lost(e.source)) continue;  // a lost rank that woke up: it is not part of the ending
      ++got;
      std::string theirs;
      const int s = decodeStatus(e.bytes, theirs);
      if (s != 0 && !reported && !theirs.empty()) {
        run = s;
        printFailure(s, e.source, ranks_, theirs);
        reported = true;
      } else if (s != 0 && run == 0) {
        run = s;
      }
    }
    if (atVerdict_) atVerdict_(run);
    const bool anyLost = live < ranks_ - 1;
    // A lost rank gets the verdict too: one that woke up then leaves quietly before the abort.
    for (int r = 1; r < ranks_; ++r) transport_->send(r, kFinishTag, encodeStatus(run, anyLost ? kLeaveWithoutFinalize : ""));
    if (anyLost) {
      (void)transport_->flush(std::min(timeout_, 10.0));
      std::fflush(stdout);
      std::fflush(stderr);
      transport_->abortAll(run);
    }
  }
  if (!transport_->flush(timeout_)) transport_->abortAll(run != 0 ? run : 1);
  transport_->finalize();
  return run;
}

void ProcessGroup::abortRun(int status, const std::string& error) {
  printFailure(status, rank_, ranks_, error);
  if (atVerdict_) atVerdict_(status);
  std::fflush(stdout);
  std::fflush(stderr);
  if (ranks_ > 1) transport_->abortAll(status);
  std::_Exit(status);
}

void ProcessGroup::markLost(int rank) {
  PR_CHECK(rank_ == 0 && rank > 0 && rank < ranks_, "rank 0 marks another rank lost");
  lost_.resize(std::size_t(ranks_), false);
  lost_[std::size_t(rank)] = true;
}

}  // namespace pr::par
