#include "paper_run.h"

#include <cmath>
#include <cstdio>

#include "ccsrm/common/error.h"
#include "ccsrm/sim_io/recorded_inputs.h"
#include "option_checks.h"

namespace ccsrm::app {

void AddPaperRunOptions(CLI::App* command, sim::PaperRunOptions* args) {
  // Command-line values are checked here, while parsing, so that an
  // out-of-range value is blamed on its option rather than on the
  // configuration file it would replace (and NaN, which PaperRunOptions
  // reads as "not given", is refused). sim::PreparePaperRun checks them
  // again with the configuration's own rules (sim/src/config.cc), naming the
  // option too; keep the bounds here in step with those.
  AddConfigOption(command, &args->config_path);
  command
      ->add_option("--case", args->case_number,
                   "Paper case: 1 no friction, 2 all friction, 3 driving cables only, 4 "
                   "connecting cables only (default: friction as configured)")
      ->check(CLI::Range(1, 4));
  command
      ->add_option(
          "--amplitude", args->amplitude_deg,
          "Planned joint amplitude [deg]: the paper protocol's (default: protocol.amplitude_deg), "
          "or a --protocol file's amplitude_deg parameter")
      ->check(InRange(-60.0, 60.0, "deg"));  // protocol.amplitude_deg
  command
      ->add_option("--duration", args->duration_s,
                   "Simulated time [s] (default: the whole protocol)")
      ->check(Above(0.0, "s"));
  // --output-rate (simulate) is registered by its command, after these; its
  // value lands in *args, so it is checked with them once parsing is done.
  // Without --config, the bundled configuration, found wherever the command
  // runs (its path is what the command names in messages and outputs).
  command->parse_complete_callback([args] {
    if (!std::isnan(args->output_rate_hz)) {
      CheckInRange("--output-rate", args->output_rate_hz, 1e-3, 1e5,
                   "Hz");  // solver.output_rate_hz
    }
    args->config_path = sim::ConfigPathOrBundled(args->config_path);
  });
}

void AddConfigOption(CLI::App* command, std::string* config_path) {
  command
      ->add_option("--config", *config_path,
                   "Arm configuration (YAML); default: the bundled paper.yaml, from the "
                   "source tree's configs/ or the installed share/ccsrm/configs")
      ->check(NotEmpty());
}

void AddParameterOptions(CLI::App* command, sim::PaperRunOptions* args) {
  std::string names;
  for (const sim::ParameterInfo& p : sim::Parameters())
    names += (names.empty() ? "" : ", ") + p.name;
  command->add_option("--set", args->sets,
                      "Parameter value, name=value (" + names +
                          ", or an effect's <effect>.<parameter>, which switches the effect "
                          "on: ccsrm generate --list-effects); repeatable, applied after the "
                          "case and --params");
  command
      ->add_option("--params", args->params_path,
                   "YAML file of parameter values (name: value, or a truth file's "
                   "'parameters:')")
      ->check(NotEmpty());
}

void AddMotionOptions(CLI::App* command, sim::PaperRunOptions* args, MotionArgs* motion) {
  CLI::Option* protocol = command->add_option(
      "--protocol", args->protocol_path,
      "Protocol file (ccsrm-protocol/1, docs/protocols.md), with optional values of its "
      "parameters after '@' (paper.yaml@ramp_s=10,hold_s=2, in the file's units); default: the "
      "bundled protocols/paper.yaml with the configuration's protocol: section");
  protocol->check(NotEmpty());
  CLI::Option* inputs = command->add_option(
      "--inputs", motion->inputs_path,
      "Recorded input lengths instead of a protocol: an experiment (/input) or run file, or a "
      "CSV/TSV table with a header (time_s or time_ms, cable1_m or cable1_mm, ...)");
  inputs->check(NotEmpty());
  protocol->excludes(inputs);
  command
      ->add_option("--inputs-time-unit", motion->time_unit,
                   "Unit of a table's time column named just 'time'")
      ->check(CLI::IsMember({"s", "ms"}));
  command
      ->add_option("--inputs-length-unit", motion->length_unit,
                   "Unit of a table's cable columns named just 'cable<k>'")
      ->check(CLI::IsMember({"m", "mm"}));
  command
      ->add_option("--max-input-gap", args->recorded_input_options.max_gap_s,
                   "Longest interval between two recorded samples [s]; a longer gap is refused")
      ->capture_default_str()
      ->check(Above(0.0, "s"));
  command->add_flag("--quasi-static", args->quasi_static,
                    "Replay settled poses: the static equilibrium at each frame, friction's "
                    "hysteresis carried from one to the next (needs solver.hole_friction: "
                    "presliding or off, and conduit_friction: presliding)");
}

sim::PaperRunOptions WithMotion(sim::PaperRunOptions options, const MotionArgs& motion) {
  if (!options.protocol_path.empty()) {
    const std::string spec = options.protocol_path;
    sim::ApplyProtocolSpec(spec, "--protocol '" + spec + "'", &options);
  }
  if (!motion.inputs_path.empty()) {
    options.recorded_input_options.time_unit = motion.time_unit;
    options.recorded_input_options.length_unit = motion.length_unit;
    options.recorded_inputs =
        sim_io::ReadRecordedInputs(motion.inputs_path, options.recorded_input_options);
  }
  return options;
}

sim::PaperRun PrepareRun(const sim::PaperRunOptions& options, const MotionArgs& motion) {
  return sim::PreparePaperRun(WithMotion(options, motion));
}

void PrintConfigWarnings(const sim::Config& config) {
  for (const std::string& w : config.warnings)
    std::fprintf(stderr, "ccsrm: warning: %s\n", w.c_str());
}

}  // namespace ccsrm::app
