#include "paper_run.h"

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/parameters.h"
#include "option_checks.h"

namespace ccsrm::app {

PaperRun PreparePaperRun(const PaperRunArgs& a) {
  std::string text = ReadTextFile(a.config_path);
  sim::Config config = sim::ParseConfig(text, a.config_path);
  if (a.case_number != 0) sim::ApplyPaperCase(a.case_number, &config);
  if (!a.params_path.empty()) {
    sim::ApplyParameterYaml(ReadTextFile(a.params_path), a.params_path, &config);
  }
  for (const std::string& assignment : a.sets) {
    const auto [name, value] = sim::ParseParameterAssignment(assignment, "--set");
    sim::SetParameter(name, value, "--set", &config);
  }
  if (!std::isnan(a.amplitude_deg)) config.protocol.amplitude_rad = a.amplitude_deg * M_PI / 180.0;
  if (!std::isnan(a.output_rate_hz)) config.solver.output_rate_hz = a.output_rate_hz;
  sim::Validate(config);
  const double duration = std::isnan(a.duration_s) ? config.protocol.duration_s() : a.duration_s;
  if (!(duration > 0.0)) ThrowInputError("--duration", "", "must be > 0 s");
  sim::ArmModel model(config);
  sim::CableInputs inputs =
      sim::PlanCableInputs(model, sim::PaperTrajectory(model, config.protocol), duration);
  return PaperRun{std::move(text), std::move(model), std::move(inputs), duration};
}

void AddPaperRunOptions(CLI::App* command, PaperRunArgs* args) {
  // Command-line values are checked here, while parsing, so that an
  // out-of-range value is blamed on its option rather than on the
  // configuration file it would replace. The bounds are those sim::Validate
  // applies to the configuration keys (sim/src/config.cc), which sim does
  // not export: keep the two in step.
  command->add_option("--config", args->config_path, "Arm configuration (YAML)")
      ->capture_default_str();
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
  command->parse_complete_callback([args] {
    if (std::isnan(args->output_rate_hz)) return;                          // not given
    CheckInRange("--output-rate", args->output_rate_hz, 1e-3, 1e5, "Hz");  // solver.output_rate_hz
  });
}

}  // namespace ccsrm::app
