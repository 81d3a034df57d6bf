// Metrics: imbalance, serial fraction, utilisation, synchronisation wait, computation-to-communication ratio and
// the scaling figures (speed-up, efficiency, Karp-Flatt), with analytic expectations.
#include <doctest/doctest.h>

#include <cmath>

#include "common/parallel/metrics.h"
#include "common/parallel/simulator.h"
#include "common/util/error.h"
#include "tests/common/parallel/parallel_test_support.h"

using namespace pr::par;

TEST_CASE("Metrics: imbalance of the seed's balanced split is 21 / 14 - 1") {
  SimOptions options;
  options.pes = 3;
  const RunSummary s = summarize(simulate(pr::test::seedExample(), "balanced", options));
  // busy 21, 13, 8: mean 14, max 21.
  CHECK(s.total.imbalance == doctest::Approx(0.5));
  CHECK(s.total.utilisation == doctest::Approx(42.0 / (3 * 21.0)));
  // PEs 1 and 2 wait 8 and 13 units at the end of the stage.
  CHECK(s.total.syncWaitSeconds == doctest::Approx(21.0));
  CHECK(s.total.figure("busySeconds").min == 8.0);
  CHECK(s.total.figure("busySeconds").max == 21.0);
  CHECK(s.total.figure("tasks").mean == 8.0);
  CHECK(s.total.computeToComm < 0.0);  // nothing was communicated
  const std::string table = formatSummary(s);
  CHECK(table.find("imbalance") != std::string::npos);
  CHECK(table.find("busySeconds") != std::string::npos);
}

TEST_CASE("Metrics: load imbalance is zero for equal or no work") {
  CHECK(loadImbalance({2.0, 2.0, 2.0}) == 0.0);
  CHECK(loadImbalance({0.0, 0.0}) == 0.0);
  CHECK(loadImbalance({1.0, 3.0}) == doctest::Approx(0.5));
}

TEST_CASE("Metrics: Amdahl's law gives back its serial fraction through Karp-Flatt") {
  // T(P) = T1 * (f + (1 - f) / P) with f = 0.1: Karp-Flatt recovers f at every P > 1.
  std::vector<ScalingPoint> points;
  for (int p : {1, 2, 4, 8, 16}) points.push_back({p, 100.0 * (0.1 + 0.9 / p)});
  const ScalingTable t = scalingTable(points, 80.0);
  REQUIRE(t.rows.size() == 5);
  CHECK(std::isnan(t.rows[0].karpFlatt));
  for (std::size_t i = 1; i < t.rows.size(); ++i) CHECK(t.rows[i].karpFlatt == doctest::Approx(0.1));
  CHECK(t.rows[1].speedup == doctest::Approx(100.0 / 55.0));
  CHECK(t.rows[1].speedupSerial == doctest::Approx(80.0 / 55.0));
  CHECK(t.rows[2].efficiency == doctest::Approx(100.0 / 32.5 / 4));
  CHECK(t.bestPes == 16);
  // 16 takes 15.625; 8 takes 21.25 (36% more): P = 16 is the first within 5% of the best.
  CHECK(t.saturationPes == 16);
  CHECK(formatScaling(t).find("Karp-Flatt") != std::string::npos);
  CHECK_THROWS_AS(scalingTable({{2, 1.0}}), pr::InputError);
}

TEST_CASE("Metrics: saturation is where adding PEs stops helping") {
  const ScalingTable t = scalingTable({{1, 10.0}, {2, 5.0}, {4, 4.0}, {8, 3.9}, {16, 4.2}});
  CHECK(t.bestPes == 8);
  CHECK(t.saturationPes == 4);  // 4.0 <= 1.05 * 3.9
}

TEST_CASE("Metrics: a serial stage is serial fraction, not imbalance, and opposite imbalances of two stages do not cancel") {
  // P = 2: a serial build (1 s on PE 0 by design), then two stages of 2 s whose busy times are
  // 2 and 1, then 1 and 2; 0.5 s between stages in the controlling thread.
  RunRecord r;
  r.pes = 2;
  r.wallSeconds = 5.5;
  const auto stage = [](const char* name, double wall, double busy0, double busy1, const char* kind) {
    StageRecord s;
    s.name = name;
    s.wallSeconds = wall;
    s.kind = kind;
    s.pes.resize(2);
    s.pes[0].busySeconds = busy0;
    s.pes[1].busySeconds = busy1;
    return s;
  };
  r.stages = {stage("build", 1.0, 1.0, 0.0, kOnePeStage), stage("a", 2.0, 2.0, 1.0, ""), stage("b", 2.0, 1.0, 2.0, "")};
  const RunSummary s = summarize(r);
  CHECK(s.stages[0].serial);
  CHECK(s.stages[0].imbalance == 0.0);
  CHECK(s.stages[1].imbalance == doctest::Approx(2.0 / 1.5 - 1.0));
  // Weighted by wall time over the parallel stages: each stage's 1/3, where the busy time summed
  // over the run (4 and 3 s) would say 1/7.
  CHECK(s.total.imbalance == doctest::Approx(1.0 / 3.0));
  CHECK(s.total.serialFraction == doctest::Approx((1.0 + 0.5) / 5.5));
  CHECK(formatSummary(s).find("serial fraction 0.2727") != std::string::npos);
}
