#pragma once
// The command-line options of every command that runs the paper's protocol
// (`simulate`, `generate`, `bench`); the run itself is sim::PreparePaperRun.
#include <CLI/CLI.hpp>

#include "ccsrm/sim/paper_run.h"

namespace ccsrm::app {

// --config, --case, --amplitude and --duration. Once parsed, an empty
// --config is the bundled configs/paper.yaml (sim::ConfigPathOrBundled).
void AddPaperRunOptions(CLI::App* command, sim::PaperRunOptions* options);

// --config alone (its help names the bundled default), for a command with
// options of its own.
void AddConfigOption(CLI::App* command, std::string* config_path);

// --params FILE and --set name=value (repeatable): named parameters (the
// table of sim/parameters.h) applied after the case.
void AddParameterOptions(CLI::App* command, sim::PaperRunOptions* options);

// What drives the arm, for `simulate`, `generate`, `bench` and
// `derivatives`: --protocol FILE or --inputs FILE (exclusive), with the
// units and gap limit of a table of inputs, and --quasi-static.
struct MotionArgs {
  std::string inputs_path;  // --inputs
  std::string time_unit;    // --inputs-time-unit
  std::string length_unit;  // --inputs-length-unit
};
void AddMotionOptions(CLI::App* command, sim::PaperRunOptions* options, MotionArgs* motion);

// The options with --protocol's spec applied (sim::ApplyProtocolSpec) and
// --inputs read (sim_io::ReadRecordedInputs): what sim::PreparePaperRun
// takes.
sim::PaperRunOptions WithMotion(sim::PaperRunOptions options, const MotionArgs& motion);

// sim::PreparePaperRun(WithMotion(options, motion)).
sim::PaperRun PrepareRun(const sim::PaperRunOptions& options, const MotionArgs& motion);

// Prints the configuration's warnings (sim::Config::warnings: values far
// outside the range of such arms) on stderr, "ccsrm: warning: ..." each.
void PrintConfigWarnings(const sim::Config& config);

}  // namespace ccsrm::app
