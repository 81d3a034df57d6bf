// Absurd requests fail at once with a message and exit 2; --max-memory bounds a load; Ctrl-C
// stops a render at once and leaves no output file (an earlier one stays as it was).
#include <doctest/doctest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "tests/test_support.h"

namespace {
// Whether the process runs `exe` and has a handler for SIGINT (the SigCgt mask of
// /proc/PID/status), polled until it does or the wait runs out. Between fork and exec the child
// still carries the test runner's own SIGINT handler, so the mask alone would say yes too early.
bool catchesSigint(pid_t pid, const std::filesystem::path& exe, std::chrono::seconds wait) {
  const auto until = std::chrono::steady_clock::now() + wait;
  const std::string proc = "/proc/" + std::to_string(pid);
  const auto target = std::filesystem::canonical(exe);
  while (std::chrono::steady_clock::now() < until) {
    std::error_code error;
    if (std::filesystem::read_symlink(proc + "/exe", error) != target) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    std::ifstream status(proc + "/status");
    for (std::string line; std::getline(status, line);) {
      if (line.rfind("SigCgt:", 0) != 0) continue;
      const unsigned long long caught = std::stoull(line.substr(7), nullptr, 16);
      if (caught & (1ull << (SIGINT - 1))) return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

const std::string kCornell = pr::test::quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf");
}

TEST_CASE("ResourceLimits: absurd render requests are refused with exit 2 and a message") {
  auto dir = pr::test::scratchDir("resource_limits");
  const std::string out = " -o " + pr::test::quoted(dir / "out.png");
  struct Case {
    const char* args;
    const char* expected;
  };
  const Case cases[] = {
      {"--width 1000000", "--width: Value 1000000 not in range 1 to 16384"},
      {"--spp 1000000000", "--spp: Value 1000000000 not in range 1 to 65535"},
      {"--threads 100000", "--threads: Value 100000 not in range 1 to 4096"},
      {"-m sort-last --width 16384 --height 16384 --threads 64",
       "a 16384 x 16384 render with sort-last at P = 64 needs 784.0 GiB, which exceeds the memory limit"},
      {"-m object --width 4096 --height 4096 --threads 8 --spp 64", "exceeds the memory limit"},
      {"--max-memory 1G -m image-space --width 8192 --height 8192",
       "a 8192 x 8192 render with image-space at P = 1, 4 spp, needs 4.0 GiB, which exceeds the memory limit of 1.0 GiB"},
      {"--max-memory 12Q", "'12Q' is not a size"},
  };
  for (const Case& c : cases) {
    SUBCASE(c.args) {
      auto result = pr::test::runParrender("render " + kCornell + " " + c.args + out);
      INFO(result.output);
      CHECK(result.exitStatus == 2);
      CHECK(result.output.find(c.expected) != std::string::npos);
      CHECK(!std::filesystem::exists(dir / "out.png"));
    }
  }
}

TEST_CASE("ResourceLimits: --max-memory refuses a load that needs more, before or after the subcommand") {
  for (const char* order : {"--max-memory 64K info ", "info --max-memory 64K "}) {
    auto result = pr::test::runParrender(std::string(order) + kCornell);
    INFO(result.output);
    CHECK(result.exitStatus == 2);
    CHECK(result.output.find("cornell.gltf needs ") != std::string::npos);
    CHECK(result.output.find("KiB, which exceeds the memory limit of 64.0 KiB (--max-memory)") != std::string::npos);
  }
  auto fits = pr::test::runParrender("--max-memory 64M info " + kCornell);
  CHECK(fits.exitStatus == 0);
}

TEST_CASE("ResourceLimits: SIGINT stops a long render promptly with exit 130 and no output file") {
  auto dir = pr::test::scratchDir("resource_limits_sigint");
  const auto out = dir / "render.png";
  std::ofstream(out) << "earlier output";
  // A render of minutes, started directly (a shell's background job would inherit SIGINT as
  // ignored) and interrupted once it runs.
  const std::string scene = (pr::test::sourceDir() / "scenes" / "cornell.gltf").string(), output = out.string();
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::execl(PARRENDER_EXE, PARRENDER_EXE, "render", scene.c_str(), "--spp", "4096", "--width", "256", "--height", "256",
            "--quiet", "-o", output.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Interrupt only once parrender's handler is in place: on a loaded machine the start-up
  // (loading the shared libraries) can take longer than any fixed wait, and a signal before it
  // kills the child.
  REQUIRE(catchesSigint(child, PARRENDER_EXE, std::chrono::seconds(60)));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto sent = std::chrono::steady_clock::now();
  ::kill(child, SIGINT);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  INFO("killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0));
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  CHECK(seconds < 5.0);  // promptly: the handler exits at once (bound generous for loaded machines)
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(text == "earlier output");
  CHECK(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()) == 1);
}
