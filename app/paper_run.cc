#include "paper_run.h"

namespace ccsrm::app {

void AddPaperRunOptions(CLI::App* command, sim::PaperRunOptions* args) {
  command->add_option("--config", args->config_path, "Arm configuration (YAML)")
      ->capture_default_str();
  command
      ->add_option("--case", args->case_number,
                   "Paper case: 1 no friction, 2 all friction, 3 driving cables only, 4 "
                   "connecting cables only (default: friction as configured)")
      ->check(CLI::Range(1, 4));
  command->add_option("--amplitude", args->amplitude_deg,
                      "Planned joint amplitude [deg] (default: protocol.amplitude_deg)");
  command->add_option("--duration", args->duration_s,
                      "Simulated time [s] (default: the whole protocol)");
}

void AddParameterOptions(CLI::App* command, sim::PaperRunOptions* args) {
  std::string names;
  for (const sim::ParameterInfo& p : sim::Parameters()) names += (names.empty() ? "" : ", ") + p.name;
  command->add_option("--set", args->sets,
                      "Parameter value, name=value (" + names +
                          "); repeatable, applied after the case and --params");
  command->add_option("--params", args->params_path,
                      "YAML file of parameter values (name: value, or a truth file's "
                      "'parameters:')");
}

}  // namespace ccsrm::app
