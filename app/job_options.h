#pragma once
// What the job commands (identify, loop, predict, design) parse and print
// alike; the jobs themselves are identify/job.h.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/identify/job.h"

namespace ccsrm::app {

// The options every fitting job takes, as given on the command line.
struct JobArgs {
  std::vector<std::string> data;
  std::optional<std::string> free;  // unset: the job's default list
  std::string params;
  std::vector<std::string> set;  // name=value
  int max_iterations = identify::IdentificationOptions().max_iterations;
  int threads = identify::DefaultThreads();
  double noise_deg = 0.0;  // 0: estimated
  double point_noise_mm = identify::ExperimentLoadOptions().point_noise_mm;
  std::string out;
  bool quiet = false;
  double run_timeout_s = identify::MpiOptions().run_timeout_s;
  bool resume = false;
};

// --threads, --noise-deg, --point-noise-mm, --out and --quiet, with their help (--data,
// --free and --resume differ by command).
void AddJobOptions(CLI::App* command, JobArgs* args);

// --params and --set of the fitting jobs.
void AddFitParameterOptions(CLI::App* command, JobArgs* args);

// The options identify and loop take alike, as their jobs take them: --free,
// --params and --set read (the list split, each assignment parsed; throws
// InputError naming the option), --noise-deg (unset when not given), the
// runs, the folder, --resume and the terminal's reporting (iteration lines
// indented by `indent`).
void FillFitJob(const JobArgs& args, const std::string& indent, identify::FitJobOptions* job);

// --noise-deg as the jobs take it (unset: estimated).
std::optional<double> NoiseOption(double noise_deg);

// Reporting on the terminal: lines on stdout, and unless `quiet` a fit's
// iteration lines (indented by `indent`, on stdout) and the per-run line (on
// stderr).
identify::JobReporting TerminalReporting(bool quiet, const std::string& indent);

// The per-simulation progress line ("simulation 3 / 8"), on stderr.
identify::RunFinishedCallback RunProgress();

// --run-timeout (MpiOptions::run_timeout_s), for the commands whose runs go
// to every rank of an MPI job.
void AddRunTimeoutOption(CLI::App* command, double* run_timeout_s);

// Prints `text` on stdout as it is, at once.
void PrintNow(const std::string& text);

}  // namespace ccsrm::app
