#include "job_options.h"

#include <cmath>
#include <cstdio>

#include "ccsrm/common/name_list.h"
#include "ccsrm/sim/parameters.h"
#include "option_checks.h"

namespace ccsrm::app {

void AddJobOptions(CLI::App* command, JobArgs* args) {
  command->add_option("--threads", args->threads, "Simulations at a time (default: every core)")
      ->check(ValidIn(&identify::IdentificationOptions::threads));
  command
      ->add_option("--noise-deg", args->noise_deg,
                   "Measurement noise of the joint angles [deg] (default: estimated per joint "
                   "from the measured twist)")
      ->check(Above(0.0, "deg"));
  command
      ->add_option("--point-noise-mm", args->point_noise_mm,
                   "Measurement noise of a tracked point's coordinates [mm] (experiments of "
                   "tracked points, e.g. a pose log's tip)")
      ->default_val(args->point_noise_mm)
      ->check(Above(0.0, "mm"));
  command->add_option("--out", args->out, "Output folder")->required();
  command->add_flag("--quiet", args->quiet, "No progress lines");
}

void AddFitParameterOptions(CLI::App* command, JobArgs* args) {
  command->add_option("--params", args->params,
                      "YAML file: name: value, or name: {value, free, bounds: [lo, hi]}");
  command->add_option("--set", args->set,
                      "Value of a parameter, name=value (start of a free one; repeatable, "
                      "applied after --params)");
}

void FillFitJob(const JobArgs& args, const std::string& indent, identify::FitJobOptions* job) {
  job->data = args.data;
  if (args.free) job->parameters.free = SplitNameList(*args.free, "--free");
  job->parameters.params_path = args.params;
  for (const std::string& text : args.set) {
    job->parameters.values.push_back(sim::ParseParameterAssignment(text, "--set"));
  }
  job->max_iterations = args.max_iterations;
  job->noise_deg = NoiseOption(args.noise_deg);
  job->point_noise_mm = args.point_noise_mm;
  job->runs = {args.threads, args.run_timeout_s};
  job->out = args.out;
  job->resume = args.resume;
  job->reporting = TerminalReporting(args.quiet, indent);
}

std::optional<double> NoiseOption(double noise_deg) {
  if (noise_deg > 0.0) return noise_deg;
  return std::nullopt;
}

void PrintNow(const std::string& text) {
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);
}

identify::RunFinishedCallback RunProgress() {
  return [](std::size_t finished, std::size_t total, const identify::RunResult& r) {
    std::fprintf(stderr, "\r  simulation %zu / %zu (%.1f s wall)", finished, total,
                 r.summary.wall_time_s);
    if (finished == total) std::fprintf(stderr, "\r%-60s\r", "");
  };
}

identify::JobReporting TerminalReporting(bool quiet, const std::string& indent) {
  identify::JobReporting reporting;
  reporting.line = PrintNow;
  if (quiet) return reporting;
  reporting.on_iteration = [indent](const identify::IterationProgress& p) {
    std::string values;
    for (const auto& [name, value] : p.values) {
      char text[96];
      std::snprintf(text, sizeof(text), " %s=%.6g", name.c_str(), value);
      values += text;
    }
    std::fprintf(stderr, "\r%-100s\r", "");
    char rms[96] = "";
    if (std::isfinite(p.rms_deg)) std::snprintf(rms, sizeof(rms), ", RMS %.4f deg", p.rms_deg);
    if (std::isfinite(p.rms_mm)) {
      std::snprintf(rms, sizeof(rms), ", points RMS %.3f mm", p.rms_mm);
    }
    std::printf("%siteration %2d: cost %.6g%s%s, %lld simulations, %.0f s;%s\n", indent.c_str(),
                p.iteration, p.cost, rms, p.step_accepted ? "" : " (step rejected)",
                static_cast<long long>(p.simulations), p.wall_time_s, values.c_str());
    std::fflush(stdout);
  };
  reporting.on_run = RunProgress();
  reporting.on_loop_progress = [](const identify::LoopProgress& p) {
    std::fprintf(stderr, "\r%-100s\r", "");
    std::printf("%s\n", p.message.c_str());
    std::fflush(stdout);
  };
  return reporting;
}

void AddRunTimeoutOption(CLI::App* command, double* run_timeout_s) {
  command
      ->add_option("--run-timeout", *run_timeout_s,
                   "Under mpirun: seconds a rank may take over one run before the job ends "
                   "with one line and exit status 7 (docs/cluster.md)")
      ->capture_default_str()
      ->check(Above(0.0, "s"));
}

}  // namespace ccsrm::app
