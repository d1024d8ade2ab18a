#pragma once
// The command-line options of every command that runs the paper's protocol
// (`simulate`, `generate`, `bench`); the run itself is sim::PreparePaperRun.
#include <CLI/CLI.hpp>

#include "ccsrm/sim/paper_run.h"

namespace ccsrm::app {

// --config, --case, --amplitude and --duration.
void AddPaperRunOptions(CLI::App* command, sim::PaperRunOptions* options);

// --params FILE and --set name=value (repeatable): named parameters (the
// table of sim/parameters.h) applied after the case.
void AddParameterOptions(CLI::App* command, sim::PaperRunOptions* options);

// Prints the configuration's warnings (sim::Config::warnings: values far
// outside the range of such arms) on stderr, "ccsrm: warning: ..." each.
void PrintConfigWarnings(const sim::Config& config);

}  // namespace ccsrm::app
