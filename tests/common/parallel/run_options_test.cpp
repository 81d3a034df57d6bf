// RunOptions: the shared command-line pieces (--schedule, --grain, --buffer-depth,
// --static-fraction, --metrics, --trace) parse into ScheduleOptions, reject unknown or
// out-of-range values with a message naming them, and list every strategy in --help.
#include <doctest/doctest.h>

#include <filesystem>

#include "common/parallel/run_options.h"
#include "common/parallel/runtime.h"
#include "tests/test_support.h"

using namespace pr::par;

namespace {

void parse(CLI::App& app, std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());  // CLI11 takes the vector form in reverse order
  app.parse(args);
}

}  // namespace

TEST_CASE("RunOptions: --schedule and --grain fill ScheduleOptions") {
  CLI::App app;
  ScheduleOptions options;
  addScheduleOptions(app, options);
  parse(app, {"--schedule", "task-manager", "--grain", "4", "--buffer-depth", "3", "--static-fraction", "0.25"});
  CHECK(options.schedule == "task-manager");
  CHECK(options.params.grain == 4);
  CHECK(options.params.bufferDepth == 3);
  CHECK(options.params.staticFraction == 0.25);
  Runtime rt(2, options.schedule, options.params);
  CHECK(rt.options().params.grain == 4);
}

TEST_CASE("RunOptions: unknown schedules and bad numbers are rejected with the valid values") {
  {
    CLI::App app;
    ScheduleOptions options;
    addScheduleOptions(app, options);
    try {
      parse(app, {"--schedule", "fastest"});
      FAIL("an unknown schedule was accepted");
    } catch (const CLI::ValidationError& e) {
      CHECK(std::string(e.what()).find("unknown schedule 'fastest'") != std::string::npos);
      CHECK(std::string(e.what()).find("preferred-bias") != std::string::npos);
    }
  }
  CLI::App app;
  ScheduleOptions options;
  addScheduleOptions(app, options);
  CHECK_THROWS_AS(parse(app, {"--grain", "0"}), CLI::ValidationError);
}

TEST_CASE("RunOptions: --help lists every schedule with its description") {
  CLI::App app;
  ScheduleOptions options;
  addScheduleOptions(app, options);
  const std::string help = app.help();
  for (const ScheduleInfo& s : schedules()) {
    CHECK(help.find(std::string(s.name)) != std::string::npos);
    CHECK(help.find(std::string(s.description)) != std::string::npos);
  }
}

TEST_CASE("RunOptions: --metrics and --trace write the run record and the trace") {
  const auto dir = pr::test::scratchDir("run_options");
  CLI::App app;
  RunOutputOptions outputs;
  addRunOutputOptions(app, outputs);
  parse(app, {"--metrics", (dir / "run.json").string(), "--trace", (dir / "trace.json").string()});
  Runtime rt(2);
  rt.runStage("s", TaskSet::uniform(4), [](Pe&, TaskId) {});
  writeRunOutputs(rt.record(), outputs);
  CHECK(readRunRecord(dir / "run.json").stages.size() == 1);
  CHECK(std::filesystem::file_size(dir / "trace.json") > 0);
}
