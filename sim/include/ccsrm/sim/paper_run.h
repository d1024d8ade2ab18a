#pragma once
// The paper's runs (section 6, SPEC 3): a configuration with one of the four
// friction cases, named parameters and overrides applied, its model, the
// planned inputs of the protocol and the simulation options; one library
// call shared by `ccsrm simulate`, `generate`, `bench`, identification and
// the tests.
#include <cmath>
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {

// The friction switches of the paper's four cases, applied to any
// parameters: 1 no friction; 2 friction on all cables (as given); 3 driving
// cables only; 4 connecting cables only. Only parameter values change (the
// equations keep their terms). Throws InputError for a case outside 1..4.
void ApplyPaperCase(int case_number, ArmParameters* parameters);

// What a paper run is made of. The fields stand for the command-line
// options of the same names, and errors name those options.
struct PaperRunOptions {
  // --config; empty: the bundled configs/paper.yaml (BundledConfigPath),
  // found wherever the program runs from.
  std::string config_path;
  int case_number = 0;          // --case; 0: friction as configured
  double amplitude_deg = NAN;   // --amplitude; NaN: protocol.amplitude_deg
  double output_rate_hz = NAN;  // --output-rate; NaN: solver.output_rate_hz
  double duration_s = NAN;      // --duration; NaN: the whole protocol
  // Named parameters (SPEC 6), applied after the case: a YAML file
  // (--params), then name=value assignments (--set).
  std::string params_path;
  std::vector<std::string> sets;
};

struct PaperRun {
  std::string config_path;  // the file read: --config, or the bundled one
  std::string config_text;  // the configuration file as given
  Config config;            // with the case, parameters and overrides applied
  ArmModel model;
  CableInputs inputs;
  SimulationOptions simulation;  // duration and solver settings of the run
  int case_number = 0;           // 0: custom
};

// Reads the configuration and builds the run. Throws InputError for a bad
// file or value.
PaperRun PreparePaperRun(const PaperRunOptions& options);

// The run in words for any arm, the lines a command prints above the
// simulation's summary: the case and the file (the paper's case only on the
// paper's arm, sim/describe.h), the arm as configured and the protocol.
std::string DescribeRun(const PaperRun& run);

// The path of the configuration `name` ("paper.yaml") that ships with ccsrm:
// in the configs/ folder of the source tree the program was built from, else
// in the installed data folder (<prefix>/share/ccsrm/configs, where `cmake
// --install` puts it). A relative default would work only from the
// repository's root. Throws InputError naming both places and asking for
// --config when neither holds it.
std::string BundledConfigPath(const std::string& name);

// `path`, or when it is empty the bundled configs/paper.yaml.
std::string ConfigPathOrBundled(const std::string& path);

}  // namespace ccsrm::sim
