// R ranks inside one test process: an in-memory Transport per rank (a queue per rank and tag)
// and a helper that runs one Runtime per rank, each on its own controlling thread, the way
// mpirun runs R copies of parrender. Lets the runtime's cross-rank code (rank_stage.cpp) be
// tested quickly and under ThreadSanitizer, beside the mpirun tests of the real transport.
#pragma once

#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/parallel/runtime.h"
#include "common/parallel/transport.h"
#include "parallel_test_support.h"

namespace pr::test {

class InProcessNetwork {
 public:
  explicit InProcessNetwork(int ranks) : boxes_(static_cast<std::size_t>(ranks)) {
    for (int r = 0; r < ranks; ++r) ends_.push_back(std::make_unique<End>(*this, r));
  }
  par::Transport& rank(int r) { return *ends_[static_cast<std::size_t>(r)]; }
  // While a rank is held nothing it sends leaves it, as from a stopped process (SIGSTOP): its
  // messages go out, in order, when it is released.
  void hold(int r, bool held) { ends_[static_cast<std::size_t>(r)]->hold(held); }

 private:
  struct Box {
    std::mutex mutex;
    std::map<int, std::deque<par::Envelope>> byTag;
  };
  class End final : public par::Transport {
   public:
    End(InProcessNetwork& net, int rank) : net_(net), rank_(rank) {}
    int rank() const override { return rank_; }
    int ranks() const override { return static_cast<int>(net_.boxes_.size()); }
    void send(int to, int tag, par::Bytes bytes) override {
      std::lock_guard lock(heldMutex_);
      if (held_)
        heldBack_.push_back({to, tag, std::move(bytes)});
      else
        deliver(to, tag, std::move(bytes));
    }
    void hold(bool held) {
      std::lock_guard lock(heldMutex_);
      held_ = held;
      if (held) return;
      for (Unsent& m : heldBack_) deliver(m.to, m.tag, std::move(m.bytes));
      heldBack_.clear();
    }
    std::optional<par::Envelope> poll(int tag) override {
      Box& box = net_.boxes_[static_cast<std::size_t>(rank_)];
      std::lock_guard lock(box.mutex);
      auto& queue = box.byTag[tag];
      if (queue.empty()) return std::nullopt;
      par::Envelope e = std::move(queue.front());
      queue.pop_front();
      return e;
    }
    bool flush(double) override { return true; }
    void finalize() override {}
    [[noreturn]] void abortAll(int) override { std::abort(); }

   private:
    void deliver(int to, int tag, par::Bytes bytes) {
      Box& box = net_.boxes_[static_cast<std::size_t>(to)];
      std::lock_guard lock(box.mutex);
      box.byTag[tag].push_back({rank_, tag, std::move(bytes)});
    }

    InProcessNetwork& net_;
    int rank_;
    struct Unsent {
      int to, tag;
      par::Bytes bytes;
    };
    std::mutex heldMutex_;
    bool held_ = false;
    std::vector<Unsent> heldBack_;  // while held
  };
  std::vector<Box> boxes_;
  std::vector<std::unique_ptr<End>> ends_;
};

// Runs body(runtime) on R ranks of T PEs each (P = R x T), one controlling thread per rank,
// and returns what each rank threw ("" for none). Ends the test binary if a rank hangs.
inline std::vector<std::string> runOnRanks(int ranks, int threadsPerRank, const std::string& schedule,
                                           const std::function<void(par::Runtime&)>& body, int grain = 1) {
  InProcessNetwork net(ranks);
  std::vector<std::string> errors(static_cast<std::size_t>(ranks));
  runWithTimeout(
      [&] {
        std::vector<std::thread> controllers;
        for (int r = 0; r < ranks; ++r)
          controllers.emplace_back([&, r] {
            try {
              par::ScheduleParams params;
              params.grain = grain;
              par::Runtime runtime(par::RuntimeOptions{ranks * threadsPerRank, schedule, params, true, &net.rank(r)});
              body(runtime);
            } catch (const std::exception& e) {
              errors[static_cast<std::size_t>(r)] = e.what();
            }
          });
        for (std::thread& t : controllers) t.join();
      },
      60.0, "runOnRanks");
  return errors;
}

}  // namespace pr::test
