#include <doctest/doctest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <iterator>

#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/interrupt.h"
#include "tests/test_support.h"

namespace {
std::string contents(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
size_t filesIn(const std::filesystem::path& dir) {
  return size_t(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()));
}
// The exit status of a child process that installs the interrupt handler, runs setUp (which
// registers what is in flight) and raises SIGINT; -1 if it did not exit.
int exitStatusAfterSigint(const std::function<void()>& setUp) {
  const pid_t child = fork();
  if (child < 0) return -1;
  if (child == 0) {
    pr::installInterruptHandler();
    setUp();
    ::raise(SIGINT);
    ::_exit(0);  // not reached: the handler exits
  }
  int status = 0;
  if (waitpid(child, &status, 0) != child || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}
}  // namespace

TEST_CASE("AtomicFile: the target appears whole on commit, a failed write leaves the old file") {
  auto dir = pr::test::scratchDir("atomic_file");
  const auto target = dir / "out.txt";
  pr::writeFileAtomically(target, "first");
  CHECK(contents(target) == "first");
  {
    pr::TempFile temp(target, "test file");
    std::ofstream(temp.path()) << "half";
    CHECK(std::filesystem::exists(temp.path()));
    // destroyed without commit: as if the write had thrown
  }
  CHECK(contents(target) == "first");
  CHECK(filesIn(dir) == 1);
  CHECK_THROWS_WITH_AS(pr::writeFileAtomically(dir / "no_such_dir" / "x.txt", "x", "test file"),
                       doctest::Contains("cannot write test file"), pr::InputError);
}

TEST_CASE("AtomicFile: SIGINT while a temporary is in flight removes it, keeps the old file, exits 130") {
  auto dir = pr::test::scratchDir("atomic_file_interrupt");
  const auto target = dir / "out.png";
  pr::writeFileAtomically(target, "earlier good output");
  CHECK(exitStatusAfterSigint([&] {
          pr::TempFile temp(target, "image file");
          std::ofstream(temp.path()) << "half written";
          ::raise(SIGINT);  // while temp is in flight
        }) == 130);
  CHECK(contents(target) == "earlier good output");
  CHECK(filesIn(dir) == 1);  // the temporary is gone
}

TEST_CASE("AtomicFile: SIGINT while a temporary folder fills removes it with everything in it") {
  auto dir = pr::test::scratchDir("atomic_file_interrupt_folder");
  const auto folder = dir / ".report.new-1";
  std::filesystem::create_directories(folder / "lib" / "deeper");
  std::filesystem::create_directories(folder / "scene");
  for (const auto& f : {folder / "index.html", folder / "lib" / "a.js", folder / "lib" / "deeper" / "b.js", folder / "scene" / "c.png"})
    std::ofstream(f) << "part";
  for (int i = 0; i < 300; ++i) std::ofstream(folder / "scene" / ("many" + std::to_string(i) + ".png")) << i;  // several batches
  std::ofstream(dir / "kept.txt") << "not the folder's";
  CHECK(exitStatusAfterSigint([&] { pr::registerTemporaryFolder(folder.c_str()); }) == 130);
  CHECK(!std::filesystem::exists(folder));
  CHECK(contents(dir / "kept.txt") == "not the folder's");
}
