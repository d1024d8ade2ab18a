// ccsrm bench: the speed figures of SPEC 10 for the paper's case 2, or of
// another protocol or recorded inputs (--protocol, --inputs).
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/simulator.h"
#include "commands.h"
#include "option_checks.h"
#include "paper_run.h"

namespace ccsrm::app {
namespace {

// Case 2 unless told otherwise (SPEC 10).
sim::PaperRunOptions CaseTwo() {
  sim::PaperRunOptions run;
  run.case_number = 2;
  return run;
}

struct BenchArgs {
  sim::PaperRunOptions run = CaseTwo();
  MotionArgs motion;
  int repeat = 3;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void RunBench(const BenchArgs& a) {
  if (a.repeat < 1) ThrowInputError("--repeat", "", "must be >= 1");
  const sim::PaperRun run = PrepareRun(a.run, a.motion);
  PrintConfigWarnings(run.config);
  const sim::Config& config = run.config;
  const sim::SimulationOptions& options = run.simulation;
  std::printf("ccsrm bench: case %d, %.4g s simulated, %d run(s), one thread\n", a.run.case_number,
              options.duration_s, a.repeat);
  std::printf("%s", sim::DescribeRun(run).c_str());
  std::vector<double> wall, rtf, rhs_rate;
  sim::SimulationSummary last;
  for (int k = 0; k < a.repeat; ++k) {
    const sim::SimulationResult result =
        sim::Simulate(run.model, config.parameters, run.inputs, options);
    last = result.summary;
    if (!last.completed())
      ThrowInputError(a.run.config_path, "", "the benchmark run diverged: " + last.message);
    wall.push_back(last.wall_time_s);
    rtf.push_back(last.real_time_factor);
    rhs_rate.push_back(last.rhs_evaluations / last.wall_time_s);
    std::printf("  run %d: wall %.2f s, real-time factor %.3f, %.0f rhs/s\n", k + 1,
                last.wall_time_s, last.real_time_factor, rhs_rate.back());
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("median wall time:          %.2f s\n", Median(wall));
  std::printf("median real-time factor:   %.3f (simulated s per wall s)\n", Median(rtf));
  std::printf("median rhs evaluations/s:  %.0f\n", Median(rhs_rate));
  std::printf("steps:                     %lld accepted, %lld rejected\n",
              static_cast<long long>(last.steps), static_cast<long long>(last.rejected_steps));
  std::printf("rhs evaluations:           %lld\n", static_cast<long long>(last.rhs_evaluations));
  std::printf("stick-slip switches:       %lld\n",
              static_cast<long long>(last.stick_slip_switches));
  std::printf("peak memory (max RSS):     %.1f MiB\n", usage.ru_maxrss / 1024.0);
}

}  // namespace

void AddBenchCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "bench",
      "Time case 2 of the configured arm and protocol (by default the paper's: +6 "
      "deg, 48 s; or --protocol, --inputs): wall time, real-time factor, "
      "right-hand-side evaluations per second, steps, peak memory");
  auto a = std::make_shared<BenchArgs>();
  AddConfigOption(cmd, &a->run.config_path);
  cmd->add_option("--case", a->run.case_number, "Paper case 1..4")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  // Checked while parsing, before the configuration is read.
  cmd->add_option("--duration", a->run.duration_s,
                  "Simulated time [s] (default: the whole protocol)")
      ->check(Above(0.0, "s"));
  cmd->add_option("--repeat", a->repeat, "Runs; medians are reported")
      ->capture_default_str()
      ->check(AtLeast(1));
  AddParameterOptions(cmd, &a->run);
  AddMotionOptions(cmd, &a->run, &a->motion);
  cmd->add_option("--output-rate", a->run.output_rate_hz,
                  "Output frames per second (default: solver.output_rate_hz); a quasi-static "
                  "replay solves a pose at each")
      ->check(InRange(1e-3, 1e5, "Hz"));  // solver.output_rate_hz
  cmd->callback([a] {
    a->run.config_path = sim::ConfigPathOrBundled(a->run.config_path);
    RunBench(*a);
  });
}

}  // namespace ccsrm::app
