// Tests of gatherToRoot (common/parallel/gather_to_root.h): every PE's list arrives at the root
// intact and in source order, and the stage's traffic is one message per non-root PE with a
// non-empty list, of the stated bytes per item.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "common/parallel/gather_to_root.h"
#include "common/parallel/runtime.h"
#include "tests/common/parallel/in_process_ranks.h"

using namespace pr;

TEST_CASE("GatherToRoot: the lists reach the root by source PE, one counted message each") {
  for (int pes : {1, 2, 3, 5}) {
    CAPTURE(pes);
    par::Runtime rt(pes);
    std::vector<std::vector<int>> lists(static_cast<size_t>(pes));
    for (int p = 0; p < pes; ++p)
      for (int i = 0; i < (p == 2 ? 0 : 10 + p); ++i) lists[size_t(p)].push_back(100 * p + i);  // PE 2 has none
    const std::vector<std::vector<int>> expected = lists;
    const std::vector<std::vector<int>> got =
        par::gatherToRoot(rt, "merge", "items", par::MessageKind::Data, std::move(lists), 8);
    CHECK(got == expected);
    uint64_t messages = 0, bytes = 0, sentItems = 0;
    for (const par::StageRecord& stage : rt.record().stages)
      if (stage.name == "merge")
        for (const par::ChannelTraffic& c : stage.channels) {
          messages += c.messages;
          bytes += c.bytes;
        }
    int senders = 0;
    for (int p = 1; p < pes; ++p)
      if (!expected[size_t(p)].empty()) {
        ++senders;
        sentItems += expected[size_t(p)].size();
      }
    CHECK(messages == uint64_t(senders));
    CHECK(bytes == sentItems * 8);
  }
}

TEST_CASE("GatherToRoot: across ranks the lists reach the root's rank by source PE, as their bytes") {
  constexpr int kRanks = 3, kThreads = 2, kPes = kRanks * kThreads;
  std::vector<std::vector<int>> expected(kPes);
  for (int p = 0; p < kPes; ++p)
    for (int i = 0; i < (p == 3 ? 0 : 5 + p); ++i) expected[size_t(p)].push_back(100 * p + i);  // PE 3 has none
  std::vector<std::vector<std::vector<int>>> got(kRanks);
  const auto errors = pr::test::runOnRanks(kRanks, kThreads, "demand", [&](par::Runtime& rt) {
    std::vector<std::vector<int>> lists(kPes);
    for (int p = rt.firstLocalPe(); p < rt.firstLocalPe() + rt.localPes(); ++p) lists[size_t(p)] = expected[size_t(p)];
    got[size_t(rt.rank())] = par::gatherToRoot(rt, "merge", "items", par::MessageKind::Data, std::move(lists), 8);
  });
  for (const std::string& e : errors) CHECK(e == "");
  CHECK(got[0] == expected);
  // The other ranks sent theirs away.
  for (int r = 1; r < kRanks; ++r)
    for (const std::vector<int>& l : got[size_t(r)]) CHECK(l.empty());
}

// gatherToAll: every rank ends with every PE's list, as root's rank holds them.
TEST_CASE("GatherToRoot: gatherToAll gives every rank every PE's list, by source PE") {
  constexpr int kRanks = 3, kThreads = 2, kPes = kRanks * kThreads;
  std::vector<std::vector<int>> expected(kPes);
  for (int p = 0; p < kPes; ++p)
    for (int i = 0; i < (p == 4 ? 0 : 3 + p); ++i) expected[size_t(p)].push_back(100 * p + i);  // PE 4 has none
  std::vector<std::vector<std::vector<int>>> got(kRanks);
  const auto errors = pr::test::runOnRanks(kRanks, kThreads, "demand", [&](par::Runtime& rt) {
    std::vector<std::vector<int>> lists(kPes);
    for (int p = rt.firstLocalPe(); p < rt.firstLocalPe() + rt.localPes(); ++p) lists[size_t(p)] = expected[size_t(p)];
    got[size_t(rt.rank())] = par::gatherToAll(rt, "merge", "items", par::MessageKind::Data, std::move(lists), 4);
  });
  for (const std::string& e : errors) CHECK(e == "");
  for (int r = 0; r < kRanks; ++r) CHECK(got[size_t(r)] == expected);
}

// shareWrittenValues: each rank wrote the values of the tasks its PEs ran (here: index i on
// rank i mod R, the others left at -1); afterwards every rank holds every value. On one rank
// the values are in place, and the record books what a run across ranks sends: each PE's
// values to PE 0 as one message, and their broadcast to every other PE.
TEST_CASE("GatherToRoot: values written where their tasks ran reach every rank") {
  constexpr int kRanks = 3, kThreads = 1, kValues = 17;
  std::vector<std::vector<double>> got(kRanks);
  const auto errors = pr::test::runOnRanks(kRanks, kThreads, "demand", [&](par::Runtime& rt) {
    std::vector<double> values(kValues, -1.0);
    for (int i = 0; i < kValues; ++i)
      if (i % kRanks == rt.rank()) values[size_t(i)] = 0.5 * i;
    par::shareWrittenValues(rt, "share", "values", values,
                            [&](std::size_t i) { return int(i) % kRanks == rt.rank() ? rt.firstLocalPe() : -1; });
    got[size_t(rt.rank())] = values;
  });
  for (const std::string& e : errors) CHECK(e == "");
  for (int r = 0; r < kRanks; ++r)
    for (int i = 0; i < kValues; ++i) CHECK(got[size_t(r)][size_t(i)] == 0.5 * i);
  par::Runtime one(2, "demand");
  std::vector<double> values{1.0, 2.0, 3.0};
  par::shareWrittenValues(one, "share", "values", values, [](std::size_t i) { return int(i % 2); });
  CHECK(values == std::vector<double>{1.0, 2.0, 3.0});
  one.runOnEachPe("after", [](par::Pe&) {});  // where the broadcast is booked
  const par::RunRecord& r = one.record();
  REQUIRE(r.stages.size() == 2);
  CHECK(r.stages[0].pes[1].messagesSent == 1);  // index 1, from PE 1
  CHECK(r.stages[0].pes[1].bytesSent == 16);  // one (index, value): the items a gathered list counts
  CHECK(r.stages[0].pes[0].messagesSent == 0);
  CHECK(r.stages[1].pes[1].broadcastsReceived == 1);
  CHECK(r.stages[1].pes[1].broadcastBytesReceived == 2 * 8 + 3 * 16);  // two lists: counts, entries
  CHECK(r.stages[1].pes[0].broadcastsReceived == 0);
  par::Runtime single(1, "demand");
  par::shareWrittenValues(single, "share", "values", values, [](std::size_t) { return 0; });
  CHECK(single.record().stages.empty());
}
