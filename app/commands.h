#pragma once
// Each group of subcommands registers itself on the root CLI11 app. Range
// checks of options run while parsing (option_checks.h); a command's
// callback throws ccsrm::InputError for bad input. main() prints either as
// one line on stderr and exits with status 2.
#include <CLI/CLI.hpp>

namespace ccsrm::app {
void AddConfigCommands(CLI::App& root);
void AddDatasetCommands(CLI::App& root);
void AddSimulateCommand(CLI::App& root);
void AddBenchCommand(CLI::App& root);
void AddMocapCommands(CLI::App& root);
void AddGenerateCommand(CLI::App& root);
void AddCamerasCommands(CLI::App& root);
void AddReportCommand(CLI::App& root);
void AddDerivativesCommand(CLI::App& root);
void AddIdentifyCommand(CLI::App& root);
void AddLoopCommand(CLI::App& root);
void AddPredictCommand(CLI::App& root);
void AddDesignCommand(CLI::App& root);
}  // namespace ccsrm::app
