#include "paper_run.h"

#include <cmath>
#include <cstdio>

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
      ->add_option("--amplitude", args->amplitude_deg,
                   "Planned joint amplitude [deg] (default: protocol.amplitude_deg)")
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
  command->add_option("--config", *config_path,
                      "Arm configuration (YAML); default: the bundled paper.yaml, from the "
                      "source tree's configs/ or the installed share/ccsrm/configs");
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
  command->add_option("--params", args->params_path,
                      "YAML file of parameter values (name: value, or a truth file's "
                      "'parameters:')");
}

void PrintConfigWarnings(const sim::Config& config) {
  for (const std::string& w : config.warnings)
    std::fprintf(stderr, "ccsrm: warning: %s\n", w.c_str());
}

}  // namespace ccsrm::app
