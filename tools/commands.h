// The subcommands of the parrender program. Each cmd_*.cpp adds one subcommand to the app:
// its options, its --help text and the callback that runs it. main.cpp calls them all.
#pragma once

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

}  // namespace pr::cli
