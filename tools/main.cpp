// parrender: the program. Parses the command line (CLI11) and runs one subcommand.
// Exit status: 0 success, 2 bad input (option, file, scene content), 1 any other failure.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "common/parallel/process_group.h"
#include "common/parallel/runtime.h"
#include "common/util/allocator.h"
#include "common/util/error.h"
#include "common/util/interrupt.h"
#include "common/util/memory_limit.h"
#include "tools/commands.h"
#include "tools/render_methods.h"

namespace pr::cli {

void requireOneRank(std::string_view command) {
  const int ranks = par::ProcessGroup::get().ranks();
  if (ranks > 1)
    throw InputError("launched as " + std::to_string(ranks) + " ranks by mpirun, but '" + std::string(command) +
                     "' does not run across processes: under mpirun, render, compare, sweep and report run across ranks (methods: " +
                     methodsAcrossRanks() + "); run " + std::string(command) + " without mpirun, with --threads P");
}

}  // namespace pr::cli

int main(int argc, char** argv) {
  pr::retainFreedMemory();
  pr::installInterruptHandler();
  // The ranks of this run: one, or those mpirun started (common/parallel/process_group.h).
  pr::par::ProcessGroup* group = nullptr;
  try {
    group = &pr::par::ProcessGroup::start(&argc, &argv);
  } catch (const std::exception& e) {
    // Every rank fails here alike: rank 0 says why.
    const int status = dynamic_cast<const pr::InputError*>(&e) ? pr::kExitBadInput : 1;
    if (pr::par::launchedRank() == 0) pr::par::printFailure(status, 0, 1, e.what());
    return status;
  }
  CLI::App app{"parrender: a parallel software renderer (sort-first/middle/last rasterizers, "
               "image-space/object-space/object ray tracers, photon maps) on one measured thread runtime"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "parrender 0.1.0");
  // Global, and accepted after the subcommand too (fallthrough); applied as soon as it is
  // parsed, so it is in force before the subcommand's callback loads anything.
  app.fallthrough();
  app.add_option_function<std::string>(
         "--max-memory", [](const std::string& v) { pr::setMemoryLimit(pr::parseByteSize(v)); },
         "memory a run may take, e.g. 512M or 8G; a file or request needing more is refused before allocating "
         "(default: 3/4 of this machine's " + pr::formatBytes(pr::physicalMemoryBytes()) + ", " +
             pr::formatBytes(pr::defaultMemoryLimit()) + ")")
      ->check(CLI::Validator(
          [](std::string& v) {
            try {
              pr::parseByteSize(v, "");
              return std::string();
            } catch (const pr::InputError& e) {
              return std::string(e.what());
            }
          },
          "SIZE"))
      ->trigger_on_parse();
  // One line per subcommand (tools/commands.h).
  pr::cli::addCompareCommand(app);
  pr::cli::addGalleryCommand(app);
  pr::cli::addGenerateCommand(app);
  pr::cli::addInfoCommand(app);
  pr::cli::addRenderCommand(app);
  pr::cli::addReportCommand(app);
  pr::cli::addSimulateCommand(app);
  pr::cli::addSweepCommand(app);

  int status = 0;
  std::string error;
  try {
    group->checkSameCommandLine(argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help, --version (status 0) and bad options (the message and a usage hint): printed by
    // rank 0 only, and every rank still ends through the group.
    const int printed = group->rank() == 0 ? app.exit(e) : e.get_exit_code();
    return group->finish(printed == 0 ? 0 : pr::kExitBadInput, "");
  } catch (const pr::InputError& e) {
    status = pr::kExitBadInput;
    error = e.what();
  } catch (const pr::par::FailedElsewhere&) {
    status = 1;  // the rank where it failed reports it
  } catch (const std::exception& e) {
    status = 1;
    error = e.what();
  }
  // Every rank ends with the run's status; rank 0 prints the failure, once.
  return group->finish(status, error);
}
