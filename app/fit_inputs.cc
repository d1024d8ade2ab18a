#include "fit_inputs.h"

#include <cstdio>
#include <filesystem>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/parameters.h"
#include "option_checks.h"

namespace ccsrm::app {

namespace fs = std::filesystem;

void ApplyFitOptions(const std::optional<std::string>& free, const std::string& params,
                     const std::vector<std::string>& set,
                     identify::IdentificationOptions* options) {
  std::vector<std::string> names;
  if (free) names = SplitList(*free, "--free");
  identify::ApplyFitParameters(free ? &names : nullptr, params, set, options);
}

std::vector<identify::Experiment> LoadExperiments(const std::vector<std::string>& paths,
                                                  double noise_deg, const char* role,
                                                  const std::string& config) {
  identify::ExperimentLoadOptions load;
  if (noise_deg > 0.0) load.noise_deg = noise_deg;
  if (!config.empty()) {
    load.config_yaml = ReadTextFile(config);
    load.config_source = config;
    sim::ParseConfig(load.config_yaml, config);  // its own errors first, naming it
  }
  std::vector<identify::Experiment> experiments;
  for (const std::string& path : paths) {
    experiments.push_back(identify::LoadExperiment(path, load));
    const identify::Experiment& e = experiments.back();
    if (e.angles_from_pipeline)
      std::printf("mocap %s: %s\n", path.c_str(), e.pipeline_report.c_str());
    double noise = 0.0;
    for (double s : e.noise_deg) noise += s / static_cast<double>(e.noise_deg.size());
    std::printf("%s %s (%s): %zu frames, %.4g s, %zu measured angles, noise %.4f deg (%s)%s\n",
                role, e.name.c_str(), path.c_str(), e.frame_time_s.size(), e.duration_s(),
                e.measured_samples, noise, e.noise_source.c_str(),
                e.angles_from_pipeline
                    ? "; no measured joint angles in the file: computed by the mocap "
                      "pipeline with default settings"
                    : "");
  }
  std::fflush(stdout);
  return experiments;
}

void PrintFitProgress(identify::IdentificationOptions* options, const std::string& indent) {
  options->on_iteration = [indent](const identify::IterationProgress& p) {
    std::string values;
    for (const auto& [name, value] : p.values) {
      char text[96];
      std::snprintf(text, sizeof(text), " %s=%.6g", name.c_str(), value);
      values += text;
    }
    std::fprintf(stderr, "\r%-100s\r", "");
    std::printf("%siteration %2d: cost %.6g, RMS %.4f deg%s, %lld simulations, %.0f s;%s\n",
                indent.c_str(), p.iteration, p.cost, p.rms_deg,
                p.step_accepted ? "" : " (step rejected)", static_cast<long long>(p.simulations),
                p.wall_time_s, values.c_str());
    std::fflush(stdout);
  };
  options->on_run = RunProgress();
}

identify::RunFinishedCallback RunProgress() {
  return [](std::size_t finished, std::size_t total, const identify::RunResult& r) {
    std::fprintf(stderr, "\r  simulation %zu / %zu (%.1f s wall)", finished, total,
                 r.summary.wall_time_s);
    if (finished == total) std::fprintf(stderr, "\r%-60s\r", "");
  };
}

void AddRunTimeoutOption(CLI::App* command, double* run_timeout_s) {
  command
      ->add_option("--run-timeout", *run_timeout_s,
                   "Under mpirun: seconds a rank may take over one run before the job ends "
                   "with one line and exit status 7 (docs/cluster.md)")
      ->capture_default_str()
      ->check(Above(0.0, "s"));
}

std::vector<std::shared_ptr<identify::SimulationBackend>> RunBackends(
    const std::vector<const std::vector<identify::Experiment>*>& sets, int threads,
    double run_timeout_s) {
  identify::MpiOptions mpi;
  mpi.threads = threads;
  mpi.run_timeout_s = run_timeout_s;
  std::vector<std::shared_ptr<identify::SimulationBackend>> backends =
      identify::ShareRuns(sets, mpi);
  if (!backends.empty() && identify::MpiRanks() > 1) {
    std::printf("runs on %d MPI ranks, %d at a time\n", identify::MpiRanks(),
                backends.front()->parallelism());
  }
  return backends;
}

}  // namespace ccsrm::app
