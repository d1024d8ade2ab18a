#pragma once
// Conversion of a simulation result to a `ccsrm-run/1` run file (SPEC 4),
// kept with the writers rather than in the simulator: identification runs
// the simulator thousands of times and never writes a file.
#include <string>

#include "ccsrm/datasets/run_file.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim_io {

// What the run file records about where the run came from.
struct RunFileInfo {
  std::string case_name = "custom";  // "1".."4" or "custom"
  std::string config_yaml;           // the full configuration used (sim::ToYaml)
  std::string protocol_yaml;         // the protocol followed (sim::Protocol::ToYaml), or empty
  std::string inputs_file;           // the recorded inputs followed, or empty
};

// What `ccsrm simulate` records of a prepared run: its case ("custom" for
// case 0), its configuration (sim::ToYaml), the protocol followed unless it
// is the configuration's own paper protocol (which config_yaml records), or
// the recorded inputs' file.
RunFileInfo PaperRunFileInfo(const sim::PaperRun& run);

// Every frame of `result.trajectory` and its solver statistics and status.
// Precondition: the trajectory was simulated on `model`.
datasets::RunFile ToRunFile(const sim::ArmModel& model, const sim::SimulationResult& result,
                            const RunFileInfo& info);

}  // namespace ccsrm::sim_io
