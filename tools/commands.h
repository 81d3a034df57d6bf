// The subcommands of the parrender program. Each cmd_*.cpp adds one subcommand to the app:
// its options, its --help text and the callback that runs it. main.cpp calls them all.
#pragma once

#include <string_view>

#include <CLI/CLI.hpp>

namespace pr::cli {

// One declaration per subcommand, each defined in its cmd_*.cpp.
void addCompareCommand(CLI::App& app);
void addGalleryCommand(CLI::App& app);
void addGenerateCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addReportCommand(CLI::App& app);
void addSimulateCommand(CLI::App& app);
void addSweepCommand(CLI::App& app);

// Under mpirun with more than one rank, throws pr::InputError for a command that does not run
// across processes, saying what does (main.cpp). Called first by every such command.
void requireOneRank(std::string_view command);

}  // namespace pr::cli
