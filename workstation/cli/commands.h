// Each visopt subcommand registers its options on a CLI11 subcommand and returns the function
// that runs it. Runners return an exit code (see cli_common.h) or throw visopt::Error.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace visopt::cli {

using Runner = std::function<int()>;

Runner addInfoCommand(CLI::App& app);
Runner addScenesCommand(CLI::App& app);
Runner addRenderCommand(CLI::App& app);
Runner addOptimizeCommand(CLI::App& app);
Runner addCompareCommand(CLI::App& app);
Runner addSdfCommand(CLI::App& app);
Runner addSessionInfoCommand(CLI::App& app);
Runner addImageDiffCommand(CLI::App& app);
Runner addMomentsCommand(CLI::App& app);

}  // namespace visopt::cli
