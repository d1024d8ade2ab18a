// ccsrm simulate: one run of the paper's protocol (or a custom amplitude and
// duration) written as a ccsrm-run/1 file.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "commands.h"

namespace ccsrm::app {
namespace {

struct SimulateArgs {
  std::string config = "configs/paper.yaml";
  int case_number = 0;  // 0: as configured
  double amplitude_deg = NAN;
  double duration_s = NAN;
  double output_rate_hz = NAN;
  std::string out;
  bool quiet = false;
};

int RunSimulate(const SimulateArgs& a) {
  sim::Config config = sim::LoadConfig(a.config);
  if (a.case_number != 0) sim::ApplyPaperCase(a.case_number, &config);
  if (!std::isnan(a.amplitude_deg)) config.protocol.amplitude_rad = a.amplitude_deg * M_PI / 180.0;
  if (!std::isnan(a.output_rate_hz)) config.solver.output_rate_hz = a.output_rate_hz;
  sim::Validate(config);
  const double duration = std::isnan(a.duration_s) ? config.protocol.duration_s() : a.duration_s;
  if (!(duration > 0.0)) ThrowInputError("--duration", "", "must be > 0 s");

  const sim::ArmModel model(config);
  const sim::CableInputs inputs =
      sim::PlanCableInputs(model, sim::PaperTrajectory(model, config.protocol), duration);
  sim::SimulationOptions options;
  options.duration_s = duration;
  options.case_name = a.case_number != 0 ? std::to_string(a.case_number) : "custom";
  if (!a.quiet) {
    options.progress = [](const sim::SimulationProgress& p) {
      std::fprintf(stderr,
                   "  t = %6.2f / %.2f s   real-time factor %.2f   steps %lld   switches %lld\n",
                   p.simulated_s, p.duration_s, p.real_time_factor, static_cast<long long>(p.steps),
                   static_cast<long long>(p.stick_slip_switches));
    };
  }
  // Check the output path before spending minutes on the run.
  { const AtomicOutputFile probe(a.out); }
  const sim::SimulationResult result = sim::Simulate(model, inputs, options);
  datasets::WriteRunFile(a.out, result.run);
  std::printf("%s", result.summary.FullReport().c_str());
  std::printf("  output:                    %s (%zu frames)\n", a.out.c_str(), result.run.frames());
  if (!result.summary.completed) {
    std::fprintf(stderr, "ccsrm: simulation diverged: %s (frames up to then are in %s)\n",
                 result.summary.message.c_str(), a.out.c_str());
    return 3;
  }
  return 0;
}

}  // namespace

void AddSimulateCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "simulate", "Simulate the arm over the paper's protocol and write a ccsrm-run/1 HDF5 file");
  auto a = std::make_shared<SimulateArgs>();
  cmd->add_option("--config", a->config, "Arm configuration (YAML)")->capture_default_str();
  cmd->add_option("--case", a->case_number,
                  "Paper case: 1 no friction, 2 all friction, 3 driving cables only, 4 connecting "
                  "cables only (default: friction as configured)")
      ->check(CLI::Range(1, 4));
  cmd->add_option("--amplitude", a->amplitude_deg,
                  "Planned joint amplitude [deg] (default: protocol.amplitude_deg)");
  cmd->add_option("--duration", a->duration_s, "Simulated time [s] (default: the whole protocol)");
  cmd->add_option("--output-rate", a->output_rate_hz,
                  "Output frames per second (default: solver.output_rate_hz)");
  cmd->add_option("--out", a->out, "Output run file (.h5)")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  cmd->callback([a] {
    const int code = RunSimulate(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
