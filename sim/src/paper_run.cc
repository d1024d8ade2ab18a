#include "ccsrm/sim/paper_run.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/sim/describe.h"

namespace ccsrm::sim {

void ApplyPaperCase(int case_number, ArmParameters* parameters) {
  if (case_number < 1 || case_number > 4) {
    ThrowInputError("--case", "", "must be 1, 2, 3 or 4, found " + std::to_string(case_number));
  }
  const bool driving = case_number == 2 || case_number == 3;
  const bool connecting = case_number == 2 || case_number == 4;
  if (!driving) parameters->mu = parameters->mu_s = 0.0;
  if (!connecting) parameters->mu_c = parameters->mu_c_s = 0.0;
}

std::string DescribeRun(const PaperRun& run) {
  const bool paper_arm = IsPaperArm(run.config.arm);
  std::string motion;
  if (run.default_protocol) {
    motion = "\n  protocol:                  " + DescribeProtocol(run.config.protocol);
  } else if (run.protocol) {
    motion = "\n  protocol:                  " + DescribeProtocolFile(*run.protocol);
  } else {
    motion =
        "\n  inputs:                    recorded, " + run.inputs_source + ": " + run.inputs_note;
  }
  return "run: " + DescribeCase(run.case_number, paper_arm) + " on " +
         (paper_arm ? "the paper's arm, " : "the arm of ") + run.config_path +
         "\n  arm:                       " + DescribeArm(run.config.arm) + motion + "\n";
}

std::string BundledConfigPath(const std::string& name) {
  // Set by CMake (sim/CMakeLists.txt): the source tree's configs/ and the
  // installed data folder, in the order they are tried.
  const std::string places[] = {CCSRM_SOURCE_CONFIG_DIR, CCSRM_INSTALLED_CONFIG_DIR};
  for (const std::string& folder : places) {
    const std::string path = folder + "/" + name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) return path;
  }
  ThrowInputError("--config", "",
                  "not given, and the bundled " + name + " is in neither " + places[0] + " nor " +
                      places[1] + ": pass --config FILE");
}

std::string ConfigPathOrBundled(const std::string& path) {
  return path.empty() ? BundledConfigPath("paper.yaml") : path;
}

std::string BundledPaperProtocolPath() { return BundledConfigPath("protocols/paper.yaml"); }

PaperRun PreparePaperRun(const PaperRunOptions& o) {
  const std::string path = ConfigPathOrBundled(o.config_path);
  return PreparePaperRun(o, ParseConfig(ReadTextFile(path), path));
}

PaperRun PreparePaperRun(const PaperRunOptions& o, Config config, const ArmModel* built) {
  const std::string path = config.source_name;
  std::string text = config.source_yaml;
  if (o.case_number != 0) ApplyPaperCase(o.case_number, &config.parameters);
  if (!o.params_path.empty()) {
    ApplyParameterYaml(ReadTextFile(o.params_path), o.params_path, &config.parameters);
  }
  for (const std::string& assignment : o.sets) {
    const auto [name, value] = ParseParameterAssignment(assignment, "--set");
    SetParameter(name, value, "--set", &config.parameters);
  }
  if (!o.protocol_path.empty() && o.recorded_inputs) {
    ThrowInputError("--protocol", "", "and --inputs exclude each other: give one");
  }
  const bool default_protocol = o.protocol_path.empty() && !o.recorded_inputs;
  ProtocolOptions protocol_options;
  if (!o.protocol_parameters.empty()) {
    if (o.protocol_path.empty()) {
      ThrowInputError(o.protocol_parameters_source, "",
                      "protocol parameters apply to a protocol file only");
    }
    protocol_options.parameters = o.protocol_parameters;
    protocol_options.parameters_source = o.protocol_parameters_source;
  }
  // Overrides are checked with the configuration's own rules, but the
  // message names the option they came from.
  if (!std::isnan(o.amplitude_deg)) {
    if (o.recorded_inputs) {
      ThrowInputError("--amplitude", "",
                      "applies to a protocol; recorded inputs (--inputs) are used as recorded");
    }
    // The conversion the paper's runs have always used, kept to the bit.
    const double amplitude_rad = o.amplitude_deg * M_PI / 180.0;
    if (default_protocol) {
      config.protocol.amplitude_rad = amplitude_rad;
      ValidateProtocol(config.protocol, "--amplitude");
    } else {
      protocol_options.parameters["amplitude_deg"] = amplitude_rad;
      protocol_options.parameters_source = "--amplitude";
    }
  }
  if (!std::isnan(o.output_rate_hz)) {
    config.solver.output_rate_hz = o.output_rate_hz;
    ValidateSolver(config.solver, "--output-rate");
  }
  // A copy of a model already built is cheap: its sparse layout is shared.
  ArmModel model = built != nullptr ? *built : ArmModel(config.arm);
  std::optional<Protocol> protocol;
  std::string inputs_note;
  std::optional<CableInputs> recorded;
  if (o.recorded_inputs) {
    // A quasi-static replay takes the recorded samples as settled poses.
    RecordedInputOptions recorded_options = o.recorded_input_options;
    recorded_options.settled_poses = recorded_options.settled_poses || o.quasi_static;
    recorded = MakeRecordedCableInputs(*o.recorded_inputs, model.num_cables(), recorded_options,
                                       &inputs_note);
    CheckRecordedInputsOnArm(*o.recorded_inputs, model, recorded_options);
  } else if (default_protocol) {
    // The configuration's protocol section sets the paper protocol's
    // parameters (SI values, as the configuration holds them).
    protocol_options.parameters = PaperProtocolParameters(config.protocol);
    protocol_options.parameters_source = path + ": protocol";
    // The user wrote the amplitude, not the bundled file: a plan it makes
    // impossible (past the joints' range) is blamed on where it came from.
    try {
      protocol = LoadProtocol(BundledPaperProtocolPath(), config.arm, protocol_options);
    } catch (const InputError& e) {
      ThrowInputError(
          std::isnan(o.amplitude_deg) ? path + ": protocol.amplitude_deg" : "--amplitude", "",
          e.what());
    }
  } else {
    protocol = LoadProtocol(o.protocol_path, config.arm, protocol_options);
  }
  const double natural_duration = protocol ? protocol->duration_s() : recorded->end_time();
  const double duration = std::isnan(o.duration_s) ? natural_duration : o.duration_s;
  if (!(duration > 0.0) || !std::isfinite(duration)) {
    ThrowInputError("--duration", "", "must be > 0 s");
  }
  CableInputs inputs = protocol ? PlanProtocolInputs(model, *protocol, config.parameters, duration)
                                : std::move(*recorded);
  SimulationOptions simulation;
  simulation.duration_s = duration;
  simulation.solver = config.solver;
  simulation.quasi_static = o.quasi_static;
  // Replaying recorded poses: a frame at each (the output rate would
  // solve poses nobody recorded).
  if (o.quasi_static && !protocol) {
    for (Eigen::Index i = 0; i < inputs.time().size(); ++i) {
      const double t = inputs.time()[i];
      if (t >= 0.0 && t <= duration) simulation.sample_times.push_back(t);
    }
  }
  PaperRun run{path,
               std::move(text),
               std::move(config),
               std::move(model),
               std::move(inputs),
               std::move(simulation),
               o.case_number,
               std::move(protocol),
               default_protocol,
               /*inputs_source=*/"",
               /*inputs_note=*/""};
  if (o.recorded_inputs) {
    run.inputs_source = o.recorded_inputs->source_name;
    run.inputs_note = inputs_note;
  }
  return run;
}

std::string ProtocolFileOf(const std::string& spec) { return spec.substr(0, spec.find('@')); }

void ApplyProtocolSpec(const std::string& spec, const std::string& where,
                       PaperRunOptions* options) {
  const std::size_t at = spec.find('@');
  options->protocol_path = ProtocolFileOf(spec);
  options->protocol_parameters_source = where;
  if (options->protocol_path.empty()) ThrowInputError(where, "", "names no protocol file");
  if (at == std::string::npos) return;
  std::size_t start = at + 1;
  while (true) {
    const std::size_t end = spec.find(',', start);
    const std::string assignment = spec.substr(start, end == std::string::npos ? end : end - start);
    const std::size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0) {
      ThrowInputError(where, "", "expected name=value after '@', found '" + assignment + "'");
    }
    const std::string name = assignment.substr(0, eq);
    double value = 0.0;
    const std::string problem = ParseNumberText(assignment.substr(eq + 1), &value);
    if (!problem.empty()) ThrowInputError(where, name, problem);
    // Protocol parameters are given in the file's units (deg for _deg).
    const bool degrees = name.size() > 4 && name.compare(name.size() - 4, 4, "_deg") == 0;
    if (!options->protocol_parameters.emplace(name, degrees ? value * M_PI / 180.0 : value)
             .second) {
      ThrowInputError(where, name, "given twice after '@'");
    }
    if (end == std::string::npos) return;
    start = end + 1;
  }
}

std::string ProtocolYamlOf(const PaperRun& run) {
  // The default (the paper protocol of the configuration's protocol:
  // section) is recorded by config_yaml itself, as in every earlier file.
  return run.protocol && !run.default_protocol ? run.protocol->ToYaml() : std::string();
}

std::vector<PlanError> PlanErrors(const PaperRun& run, const Trajectory& trajectory) {
  std::vector<PlanError> errors;
  if (!run.protocol || trajectory.size() == 0) return errors;
  const Protocol& protocol = *run.protocol;
  std::vector<double> sum_sq(protocol.segment_joints.size(), 0.0);
  std::vector<std::size_t> count(protocol.segment_joints.size(), 0);
  for (std::size_t s = 0; s < protocol.segment_joints.size(); ++s) {
    errors.push_back({static_cast<int>(s) + 1});
  }
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    const JointAngles plan = protocol.PlannedAngles(trajectory.time[f]);
    const std::vector<Eigen::Vector2d>& angles = trajectory.frames[f].joint_angles;
    int joint = 0;
    for (std::size_t s = 0; s < protocol.segment_joints.size(); ++s) {
      for (int j = 0; j < protocol.segment_joints[s]; ++j, ++joint) {
        for (int a = 0; a < 2; ++a) {
          const double e =
              angles[static_cast<std::size_t>(joint)][a] - plan[static_cast<std::size_t>(joint)][a];
          sum_sq[s] += e * e;
          ++count[s];
          if (std::abs(e) > errors[s].max_abs_rad) {
            errors[s].max_abs_rad = std::abs(e);
            errors[s].worst_joint = joint + 1;
            errors[s].worst_axis = a;
            errors[s].worst_time_s = trajectory.time[f];
          }
        }
      }
    }
  }
  for (std::size_t s = 0; s < errors.size(); ++s) {
    errors[s].rms_rad = count[s] > 0 ? std::sqrt(sum_sq[s] / static_cast<double>(count[s])) : 0.0;
  }
  return errors;
}

std::string DescribeRunStates(const PaperRun& run, const SimulationResult& result) {
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  std::string out;
  char line[256];
  for (const PlanError& e : PlanErrors(run, result.trajectory)) {
    std::snprintf(line, sizeof(line),
                  "  error to the plan, seg. %d: RMS %.3g deg, largest %.3g deg (joint %d %s at "
                  "%.2f s)\n",
                  e.segment, e.rms_rad * kDeg, e.max_abs_rad * kDeg, e.worst_joint,
                  e.worst_axis == 0 ? "θx" : "θy", e.worst_time_s);
    out += line;
  }
  int holes = 0, most = 0;
  double most_at = 0.0;
  for (const DrivingCableModel& c : run.model.cables()) holes += c.num_holes();
  for (std::size_t f = 0; f < result.trajectory.size(); ++f) {
    int stuck = 0;
    for (const std::vector<int>& cable : result.trajectory.frames[f].hole_stuck) {
      for (int s : cable) stuck += s != 0;
    }
    if (stuck > most) {
      most = stuck;
      most_at = result.trajectory.time[f];
    }
  }
  if (holes > 0) {
    std::snprintf(line, sizeof(line),
                  "  stuck hole nodes:          at most %d of %d (t = %.2f s)%s\n", most, holes,
                  most_at,
                  run.config.solver.hole_friction == HoleFrictionModel::kEvents
                      ? ""
                      : "; this law sticks without switch events");
    out += line;
  }
  return out;
}

}  // namespace ccsrm::sim
