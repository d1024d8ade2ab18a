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
#include "ccsrm/sim_io/run_file.h"
#include "commands.h"
#include "option_checks.h"
#include "output_kinds.h"
#include "paper_run.h"

namespace ccsrm::app {
namespace {

struct SimulateArgs {
  sim::PaperRunOptions run;
  MotionArgs motion;
  std::string out;
  bool quiet = false;
};

int RunSimulate(const SimulateArgs& a) {
  // Check the output path before spending minutes on the run.
  CheckOut(a.out, datasets::RunFileOutput(),
           {a.run.config_path, a.run.params_path, sim::ProtocolFileOf(a.run.protocol_path),
            a.motion.inputs_path});
  const sim::PaperRun run = PrepareRun(a.run, a.motion);
  PrintConfigWarnings(run.config);
  sim::SimulationOptions options = run.simulation;
  if (!a.quiet) {
    options.progress = [](const sim::SimulationProgress& p) {
      std::fprintf(stderr,
                   "  t = %6.2f / %.2f s   real-time factor %.2f   steps %lld   switches %lld\n",
                   p.simulated_s, p.duration_s, p.real_time_factor, static_cast<long long>(p.steps),
                   static_cast<long long>(p.stick_slip_switches));
    };
  }
  const sim::SimulationResult result =
      sim::Simulate(run.model, run.config.parameters, run.inputs, options);
  if (result.trajectory.size() == 0) {
    // A run file needs a frame: say why there is none instead.
    std::printf("%s", result.summary.FullReport().c_str());
    std::fprintf(stderr, "ccsrm: simulation diverged before its first frame: %s (%s not written)\n",
                 result.summary.message.c_str(), a.out.c_str());
    return 3;
  }
  datasets::WriteRunFile(a.out,
                         sim_io::ToRunFile(run.model, result, sim_io::PaperRunFileInfo(run)));
  std::printf("%s", sim::DescribeRun(run).c_str());
  std::printf("%s", result.summary.FullReport().c_str());
  std::printf("%s", sim::DescribeRunStates(run, result).c_str());
  std::printf("  output:                    %s (%zu frames)\n", a.out.c_str(),
              result.trajectory.size());
  if (!result.summary.completed()) {
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
  AddPaperRunOptions(cmd, &a->run);
  AddParameterOptions(cmd, &a->run);
  AddMotionOptions(cmd, &a->run, &a->motion);
  // NaN is PaperRunOptions' "not given": a typed "nan" is refused here.
  cmd->add_option("--output-rate", a->run.output_rate_hz,
                  "Output frames per second (default: solver.output_rate_hz)")
      ->check(InRange(1e-3, 1e5, "Hz"));  // solver.output_rate_hz
  cmd->add_option("--out", a->out, "Output run file (.h5)")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  cmd->callback([a] {
    const int code = RunSimulate(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
