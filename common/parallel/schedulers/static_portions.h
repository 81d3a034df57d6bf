// StaticPortionScheduler: the data-driven models' common mechanics — every PE's portion is
// fixed in reset() and sent as one task packet on the PE's first request (seed 3.2.1, 3.4.1).
// balanced.cpp, unbalanced.cpp and owner_pinned.cpp differ only in the split they pass in.
#pragma once

#include <functional>
#include <string_view>
#include <vector>

#include "common/parallel/schedulers/scheduler.h"

namespace pr::par {

class StaticPortionScheduler : public Scheduler {
 public:
  using Split = std::function<std::vector<std::vector<TaskId>>(const TaskSet&, int pes)>;
  StaticPortionScheduler(std::string_view name, Split split) : name_(name), split_(std::move(split)) {}
  std::string_view name() const override { return name_; }
  bool decidedPerPe() const override { return true; }

  void reset(const TaskSet& tasks, int pes, const ScheduleParams&) override {
    portions_ = split_(tasks, pes);
    sent_.assign(pes, 0);
  }

  // Each PE touches only its own portion and flag: no synchronisation needed.
  void next(int pe, double, Grab& out) override {
    out.clear();
    if (sent_[pe] || portions_[pe].empty()) return;
    sent_[pe] = 1;
    out.tasks = portions_[pe];
    out.packets = 1;  // sent by the controller unprompted: no request
    out.moved = out.tasks.size();
  }

 private:
  std::string_view name_;
  Split split_;
  std::vector<std::vector<TaskId>> portions_;
  std::vector<char> sent_;
};

}  // namespace pr::par
