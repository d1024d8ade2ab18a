#pragma once
// What `simulate` and `bench` both need: a configuration with a paper case
// and command-line overrides applied, its model, and the planned inputs.
#include <cmath>
#include <string>

#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::app {

struct PaperRunArgs {
  std::string config_path = "configs/paper.yaml";
  int case_number = 0;          // 0: friction as configured
  double amplitude_deg = NAN;   // NaN: protocol.amplitude_deg
  double output_rate_hz = NAN;  // NaN: solver.output_rate_hz
  double duration_s = NAN;      // NaN: the whole protocol
};

struct PaperRun {
  sim::ArmModel model;
  sim::CableInputs inputs;
  double duration_s;
};

// Throws InputError for a bad file or value.
PaperRun PreparePaperRun(const PaperRunArgs& args);

}  // namespace ccsrm::app
