// StaticPortionScheduler: the data-driven models' common mechanics — every PE's portion is
// fixed in reset() before the computation starts (seed 3.2.1, 3.4.1), a pure function of the
// task set and P that every PE holds, so each PE takes its own portion where it is: no task
// request or packet travels, on threads, across ranks or in the simulator (what the seed's
// initial distribution moves is the principal data, which the methods' own stages carry).
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
    out.from = pe;  // its own portion: nothing is asked or sent
    out.blocking = false;
  }

 private:
  std::string_view name_;
  Split split_;
  std::vector<std::vector<TaskId>> portions_;
  std::vector<char> sent_;
};

}  // namespace pr::par
