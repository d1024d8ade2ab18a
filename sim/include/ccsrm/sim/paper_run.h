#pragma once
// The paper's runs (section 6, SPEC 3): a configuration with one of the four
// friction cases, named parameters and overrides applied, its model, the
// planned inputs of the protocol and the simulation options; one library
// call shared by `ccsrm simulate`, `generate`, `bench`, identification and
// the tests.
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {

// The friction switches of the paper's four cases, applied to any
// parameters: 1 no friction; 2 friction on all cables (as given); 3 driving
// cables only; 4 connecting cables only. Only parameter values change (the
// equations keep their terms). Throws InputError for a case outside 1..4.
void ApplyPaperCase(int case_number, ArmParameters* parameters);

// What a paper run is made of. The fields stand for the command-line
// options of the same names, and errors name those options.
//
// The motion: without protocol_path and recorded_inputs, the bundled
// configs/protocols/paper.yaml with its parameters (amplitude_deg, ramp_s,
// hold_s, return_s, rest_s) set from the configuration's `protocol:`
// section, and amplitude_deg from --amplitude when given: the paper's
// protocol as before, to the bit. With protocol_path, that file as written
// (the configuration's `protocol:` section plays no part), --amplitude
// setting its amplitude_deg parameter (refused when it has none). With
// recorded_inputs, those lengths (--amplitude is refused).
struct PaperRunOptions {
  // --config; empty: the bundled configs/paper.yaml (BundledConfigPath),
  // found wherever the program runs from.
  std::string config_path;
  int case_number = 0;          // --case; 0: friction as configured
  double amplitude_deg = NAN;   // --amplitude; NaN: the protocol's own (see above)
  double output_rate_hz = NAN;  // --output-rate; NaN: solver.output_rate_hz
  // --duration; NaN: the whole protocol, or up to the last recorded sample.
  // Beyond the protocol's end the arm holds its last planned state (the
  // last recorded lengths).
  double duration_s = NAN;
  // --protocol: a ccsrm-protocol/1 file; empty: see above.
  std::string protocol_path;
  // Values of the protocol file's `parameters:` (SI: rad for a name ending
  // in _deg), as ProtocolOptions::parameters; a name the file does not
  // declare is refused, blamed on protocol_parameters_source.
  std::map<std::string, double> protocol_parameters;
  std::string protocol_parameters_source = "--protocol";
  // --inputs, read by the command (sim_io::ReadRecordedInputs), and how its
  // samples are checked and resampled. Exclusive with protocol_path.
  std::optional<RecordedInputs> recorded_inputs;
  RecordedInputOptions recorded_input_options;
  // Named parameters (SPEC 6), applied after the case: a YAML file
  // (--params), then name=value assignments (--set).
  std::string params_path;
  std::vector<std::string> sets;
  // --quasi-static: the run replays settled poses
  // (SimulationOptions::quasi_static).
  bool quasi_static = false;
};

struct PaperRun {
  std::string config_path;  // the file read: --config, or the bundled one
  std::string config_text;  // the configuration file as given
  Config config;            // with the case, parameters and overrides applied
  ArmModel model;
  CableInputs inputs;
  SimulationOptions simulation;  // duration and solver settings of the run
  int case_number = 0;           // 0: custom
  // The protocol followed, and its file (the bundled paper.yaml by
  // default); absent with recorded inputs.
  std::optional<Protocol> protocol;
  bool default_protocol = false;  // the configuration's paper protocol
  // Recorded inputs: their file and how the samples were used; else empty.
  std::string inputs_source;
  std::string inputs_note;
};

// The protocol grammar of the command line and of design plans: a protocol
// given as "file.yaml" or "file.yaml@name=value,name=value" (the file's
// parameters in its units, deg for names ending in _deg). Sets
// options->protocol_path and protocol_parameters; errors name `where` (the
// option and the spec as given). Throws InputError.
void ApplyProtocolSpec(const std::string& spec, const std::string& where, PaperRunOptions* options);

// The file of such a protocol spec (what precedes '@').
std::string ProtocolFileOf(const std::string& spec);

// Reads the configuration and builds the run. Throws InputError for a bad
// file or value.
PaperRun PreparePaperRun(const PaperRunOptions& options);

// The same from a configuration already read (LoadConfig / ParseConfig):
// its source_name and source_yaml stand for the file, and
// options.config_path is not used. `model`, when not null, is the model of
// config.arm already built (precondition), used instead of building it
// again. For callers that hold the configuration and its model (the Python
// module) and must not read the file or rebuild the model for every run.
PaperRun PreparePaperRun(const PaperRunOptions& options, Config config,
                         const ArmModel* model = nullptr);

// What a run file or experiment records of the motion that drove the run:
// the protocol as followed (its parameters as used), or empty for the
// configuration's paper protocol (config_yaml records it) and for recorded
// inputs (their file is recorded instead).
std::string ProtocolYamlOf(const PaperRun& run);

// The run in words for any arm, the lines a command prints above the
// simulation's summary: the case and the file (the paper's case only on the
// paper's arm, sim/describe.h), the arm as configured and the protocol (or
// the recorded inputs) followed.
std::string DescribeRun(const PaperRun& run);

// How far a run's joints came from the protocol's plan, per segment: the
// largest |angle - plan| over its joints, both axes and every frame, where
// and when, and the RMS over the same [rad]. Empty for recorded inputs (no
// plan).
struct PlanError {
  int segment = 0;  // 1-based
  double max_abs_rad = 0.0;
  int worst_joint = 0;  // 1-based, of the arm
  int worst_axis = 0;   // 0 θx, 1 θy
  double worst_time_s = 0.0;
  double rms_rad = 0.0;
};
std::vector<PlanError> PlanErrors(const PaperRun& run, const Trajectory& trajectory);

// The lines `ccsrm simulate` prints below the simulation's summary: the
// error to the plan per segment, and the stuck hole nodes the run's states
// hold (under the presliding and smoothed laws, which switch without
// events, the switch counter above stays 0 while nodes stick).
std::string DescribeRunStates(const PaperRun& run, const SimulationResult& result);

// The path of the configuration `name` ("paper.yaml") that ships with ccsrm:
// in the configs/ folder of the source tree the program was built from, else
// in the installed data folder (<prefix>/share/ccsrm/configs, where `cmake
// --install` puts it). A relative default would work only from the
// repository's root. Throws InputError naming both places and asking for
// --config when neither holds it.
std::string BundledConfigPath(const std::string& name);

// `path`, or when it is empty the bundled configs/paper.yaml.
std::string ConfigPathOrBundled(const std::string& path);

// The bundled configs/protocols/paper.yaml (BundledConfigPath).
std::string BundledPaperProtocolPath();

}  // namespace ccsrm::sim
