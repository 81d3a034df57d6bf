// The process group across real processes: mpirun on loopback (--oversubscribe, root allowed
// as in CI), every command bounded by `timeout` so a failure can never hang the suite.
#include <chrono>
#include <string>
#include <utility>

#include <doctest/doctest.h>

#include "mpirun_support.h"

namespace {

using pr::test::CommandResult;
using pr::test::kMpiEnv;
using pr::test::mpirun;
using pr::test::occurrences;
using pr::test::quoted;

std::string check() { return quoted(pr::test::binaryDir() / "tests" / "parrender_transport_check"); }
std::string parrender() { return quoted(PARRENDER_EXE); }

}  // namespace

TEST_CASE("ProcessGroup: 2 and 3 ranks exchange messages of 0 B to 1 MiB through MPI, every byte as sent") {
  for (int ranks : {2, 3}) {
    CAPTURE(ranks);
    const CommandResult r = mpirun(ranks, check(), "exchange");
    INFO(r.output);
    CHECK(r.exitStatus == 0);
    CHECK(r.output.find("exchange: " + std::to_string(ranks) + " ranks") != std::string::npos);
  }
}

TEST_CASE("ProcessGroup: a rank that fails ends every rank, with one message from rank 0 naming it") {
  const CommandResult r = mpirun(3, check(), "fail 1");
  INFO(r.output);
  CHECK(r.exitStatus == 1);
  CHECK(occurrences(r.output, "parrender: failed (rank 1 of 3): an injected failure") == 1);
}

TEST_CASE("ProcessGroup: a rank that stops answering ends every rank after the bounded wait, no hang") {
  const auto t0 = std::chrono::steady_clock::now();
  const CommandResult r = mpirun(2, check(), "hang 1", 60, "PARRENDER_RANK_TIMEOUT=2");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(r.output);
  CHECK(r.exitStatus != 0);
  CHECK(r.exitStatus != 124);  // ended by the group, not by the test's timeout
  CHECK(r.output.find("no answer within 2 s") != std::string::npos);
  CHECK(seconds < 30.0);
}

TEST_CASE("ProcessGroup: parrender under mpirun checks that every rank got the same options, and a command that does not run across ranks says so") {
  const std::string cornell = quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf");
  const std::string glass = quoted(pr::test::sourceDir() / "scenes" / "cornell-glass.gltf");
  const CommandResult differ = pr::test::runCommand(
      kMpiEnv + "timeout 60 mpirun --oversubscribe -np 1 " + parrender() +
      " info " + cornell + " : -np 1 " + parrender() + " info " + glass);
  INFO(differ.output);
  CHECK(differ.exitStatus == 2);
  CHECK(occurrences(differ.output, "parrender: error") == 1);
  CHECK(differ.output.find("rank 1 was started with a different command line") != std::string::npos);

  const CommandResult same = mpirun(2, parrender(), "info " + cornell);
  INFO(same.output);
  CHECK(same.exitStatus == 2);
  CHECK(occurrences(same.output, "parrender: error (rank 0 of 2)") == 1);
  CHECK(same.output.find("'info' does not run across processes") != std::string::npos);

  // One rank is today's program.
  const CommandResult one = mpirun(1, parrender(), "info " + cornell);
  INFO(one.output);
  CHECK(one.exitStatus == 0);
  CHECK(one.output.find("triangles") != std::string::npos);
}

TEST_CASE("ProcessGroup: the runtime's stages across 2 and 3 ranks run every task once and end after every message") {
  for (const auto& shape : {std::pair{2, 1}, std::pair{3, 1}, std::pair{2, 2}}) {
    const int ranks = shape.first, threads = shape.second;  // CAPTURE cannot take a structured binding
    CAPTURE(ranks);
    CAPTURE(threads);
    const CommandResult r = mpirun(ranks, check(), "stages " + std::to_string(threads));
    INFO(r.output);
    CHECK(r.exitStatus == 0);
    CHECK(occurrences(r.output, "tasks once each") == 4);
  }
}

TEST_CASE("ProcessGroup: a task that fails on one rank's PE ends the stage on every rank, rank 0 names it once") {
  const CommandResult r = mpirun(2, check(), "stagefail 3");
  INFO(r.output);
  CHECK(r.exitStatus == 1);
  CHECK(occurrences(r.output, "parrender: failed (rank 1 of 2): an injected task failure") == 1);
  CHECK(occurrences(r.output, "parrender: failed") == 1);
}

// Work on rank 0 alone (a one-PE baseline of compare, a look in the reference cache) may take
// longer than any one wait may last: rank 0 tells the others it is working, and its result
// reaches every rank; its failure ends every rank with one message.
TEST_CASE("ProcessGroup: work on rank 0 alone outlasts the bounded wait while the others wait, and its result reaches every rank") {
  const CommandResult r = mpirun(3, check(), "alone 3", 60, "PARRENDER_RANK_TIMEOUT=1");
  INFO(r.output);
  CHECK(r.exitStatus == 0);
  CHECK(occurrences(r.output, "got rank 0's result") == 3);
  const CommandResult fail = mpirun(2, check(), "alonefail 0", 60, "PARRENDER_RANK_TIMEOUT=5");
  INFO(fail.output);
  CHECK(fail.exitStatus == 1);
  CHECK(occurrences(fail.output, "parrender: failed (rank 0 of 2): an injected failure alone") == 1);
  CHECK(occurrences(fail.output, "parrender: failed") == 1);
}
