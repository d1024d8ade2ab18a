#pragma once
// What `simulate`, `generate` and `bench` need: a configuration with a paper
// case, named parameters and command-line overrides applied, its model, and
// the planned inputs.
#include <CLI/CLI.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::app {

struct PaperRunArgs {
  std::string config_path = "configs/paper.yaml";
  int case_number = 0;          // 0: friction as configured
  double amplitude_deg = NAN;   // NaN: protocol.amplitude_deg
  double output_rate_hz = NAN;  // NaN: solver.output_rate_hz
  double duration_s = NAN;      // NaN: the whole protocol
  // Named parameters (SPEC 6), applied after the case: a YAML file, then
  // name=value assignments.
  std::string params_path;
  std::vector<std::string> sets;
};

struct PaperRun {
  std::string config_text;  // the configuration file as given
  sim::ArmModel model;      // with the case, parameters and overrides applied
  sim::CableInputs inputs;
  double duration_s;
};

// Throws InputError for a bad file or value.
PaperRun PreparePaperRun(const PaperRunArgs& args);

// --config, --case, --amplitude and --duration, the options every command
// that runs the paper's protocol takes.
void AddPaperRunOptions(CLI::App* command, PaperRunArgs* args);

}  // namespace ccsrm::app
