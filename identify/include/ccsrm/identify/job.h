#pragma once
// The jobs of identification (identify, loop, design, predict) as every door runs
// them. The command line and the Python module each parse their options,
// make one call here and print what it returns, so the two cannot drift
// (STYLE.md, "A job ... is one library function"). A job:
//   1. checks its options and its output folder against the one output
//      policy (common/output_policy.h) before any work;
//   2. loads every experiment once (its configuration read and checked
//      once, before the first experiment);
//   3. resumes from the folder's checkpoint or journal when asked;
//   4. picks where its runs go: threads here, or every rank of an MPI job
//      (identify::ShareRuns; the command's process started MPI);
//   5. runs, and writes its folder atomically.
// Each throws InputError (one line naming the file and field, or the
// option) for bad input; numerical outcomes (a fit that did not converge)
// are in the summary.
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/common/output_policy.h"
#include "ccsrm/identify/design.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/identify/loop.h"
#include "ccsrm/identify/mpi_backend.h"
#include "ccsrm/identify/prediction.h"

namespace ccsrm::identify {

// What a job says while it works. Every field may be empty (Python's
// default: a job says nothing).
struct JobReporting {
  // Text for the user, whole lines each ending in '\n' (the commands print
  // it on stdout as it comes): what was loaded, where the runs go, the
  // summary, what was written.
  std::function<void(const std::string&)> line;
  // A fit's iteration, and each finished run (the commands print both).
  std::function<void(const IterationProgress&)> on_iteration;
  RunFinishedCallback on_run;
  // The loop's progress lines.
  std::function<void(const LoopProgress&)> on_loop_progress;
};

// A fit's parameters as a door gives them, applied in this order.
struct FitParameterChoice {
  // The free parameters by SPEC 6 name; unset: the job's default list.
  std::optional<std::vector<std::string>> free;
  // A parameter file (name: value, or name: {value, free, bounds}); empty:
  // none.
  std::string params_path;
  // Values by name (start values of free ones), after params_path: `--set
  // name=value`, or a Python dict, as numbers.
  std::vector<std::pair<std::string, double>> values;
};

// Where a job's runs go.
struct JobRuns {
  // Simulations at a time on this machine (on each rank under MPI).
  // Default: every core.
  int threads = DefaultThreads();
  // Under mpirun: how long a rank may take over one run [s]
  // (MpiOptions::run_timeout_s).
  double run_timeout_s = MpiOptions().run_timeout_s;
};

// What the fitting jobs (identify, loop) take alike.
struct FitJobOptions {
  // Experiment files (ccsrm-dataset/1), one or more: the fitted (training)
  // data.
  std::vector<std::string> data;
  FitParameterChoice parameters;
  int max_iterations = IdentificationOptions().max_iterations;  // per fit
  // Measurement noise of the joint angles [deg]; unset: estimated per joint.
  std::optional<double> noise_deg;
  // Measurement noise of tracked points' coordinates [mm]
  // (ExperimentLoadOptions::point_noise_mm).
  double point_noise_mm = ExperimentLoadOptions().point_noise_mm;
  JobRuns runs;
  // The job's folder; empty: not written (then no checkpoint or journal
  // either).
  std::string out;
  // Continue the job stopped in `out` (identify: from its checkpoint.json;
  // loop: running again over the journal of its runs).
  bool resume = false;
  JobReporting reporting;
};

// `ccsrm identify` (README, docs/cluster.md for --resume).
struct IdentifyJobOptions : FitJobOptions {
  double relative_step = IdentificationOptions().relative_step;
  bool central_differences_throughout = false;
};

// What a job returns. On a rank other than 0 of an MPI job, `served` is
// true once it has served rank 0's runs, and nothing else is set.
struct IdentifyJobResult {
  bool served = false;
  IdentificationSummary summary;
  std::vector<Experiment> experiments;
  std::vector<std::string> written;  // the folder's files (empty without `out`)
};

IdentifyJobResult RunIdentifyJob(const IdentifyJobOptions& options);

// `ccsrm loop` (docs/loop.md). `parameters` are the declared model's.
struct LoopJobOptions : FitJobOptions {
  std::vector<std::string> holdout;  // held-out experiments (may be none)
  // Candidate effects ('declared', 'terms' among them); unset: every one.
  std::optional<std::vector<std::string>> candidates;
  // The declared arm configuration instead of each recording's own; empty:
  // each file's config_yaml.
  std::string config_path;
  int max_rounds = LoopOptions().max_rounds;
};

struct LoopJobResult {
  bool served = false;  // as IdentifyJobResult's
  LoopSummary summary;
  std::vector<Experiment> training, holdout;
  std::vector<std::string> written;
  // Runs simulated, and taken from the journal of a stopped loop.
  std::int64_t simulated = 0, replayed = 0;
};

LoopJobResult RunLoopJob(const LoopJobOptions& options);

// `ccsrm design` (README, docs/design.md).
struct DesignJobOptions {
  // The prior, as a paper run takes it (sim::PaperRunOptions): the arm
  // (empty: the bundled paper.yaml), a paper case (0: friction as
  // configured), a parameter file (empty: none) and name=value assignments
  // after it.
  std::string config_path;
  int case_number = 0;
  std::string params_path;
  std::vector<std::string> sets;
  // Candidate plans, each protocol specs (sim::ApplyProtocolSpec) joined by
  // '+', one experiment each. May be empty with `propose`.
  std::vector<std::string> plans;
  // Also search `space` (ProposalCandidates) and write the best proposed
  // motion.
  bool propose = false;
  ProposalSpace space;
  // What is estimated and how the recordings would be made (the free
  // parameters, noise, prior box, ...); threads, backend and on_run are the
  // job's (from `runs` and `reporting`).
  DesignOptions design;
  // A fit.json of recordings like those planned (RecordingNoiseOf): its
  // noise and N_eff / N replace design.noise_deg and
  // effective_sample_fraction. Empty: none.
  std::string noise_from;
  JobRuns runs;
  std::string out;  // the design folder (required)
  // Run again over the journal of the design stopped in `out`.
  bool resume = false;
  JobReporting reporting;
};

struct DesignJobResult {
  bool served = false;  // as IdentifyJobResult's
  DesignSummary summary;
  std::vector<std::string> skipped;  // proposed points left out, with why
  std::vector<std::string> written;
  std::int64_t simulated = 0, replayed = 0;  // as LoopJobResult's
};

DesignJobResult RunDesignJob(const DesignJobOptions& options);

// The design folder: design.json (ToJson, with the prior's configuration
// for the report's page) and, when a proposed motion completed, the best as
// proposed.yaml and proposed.inputs.csv (PlannedMotionCsv). Replaces `out`
// as a whole. Returns the files written.
std::vector<std::string> WriteDesignDirectory(const DesignSummary& summary,
                                              const sim::Config& prior, const std::string& out);

// `ccsrm predict`.
struct PredictJobOptions {
  std::vector<std::string> data;  // recordings to predict, one or more
  // The model: a fit.json, a fit or loop folder, or a parameter file.
  std::string params_path;
  std::string effects_path;  // effects switched on over the model; empty: none
  std::string config_path;   // instead of each recording's own; empty: none
  std::optional<double> noise_deg;
  double point_noise_mm = ExperimentLoadOptions().point_noise_mm;  // as FitJobOptions'
  int threads = PredictionOptions().threads;
  std::string out;  // the prediction folder; empty: not written
  JobReporting reporting;
};

struct PredictJobResult {
  PredictionSummary summary;
  std::vector<Experiment> recordings;
  std::vector<std::string> written;
};

PredictJobResult RunPredictJob(const PredictJobOptions& options);

// The folders the jobs write, for the output policy: each recognises an
// earlier output of its own kind (or a folder a stopped job left its
// checkpoint in), which the job replaces; anything else is refused.
OutputKind FitFolderOutput();         // fit.json, ccsrm-fit/1
OutputKind LoopFolderOutput();        // loop.json, ccsrm-loop/1
OutputKind PredictionFolderOutput();  // pred.json, ccsrm-prediction/1
OutputKind DesignFolderOutput();      // design.json, ccsrm-design/1

// Loads each experiment (ExperimentLoadOptions: the given noises) and reports one line about
// it through `line` (and the mocap pipeline's when it computed the angles).
// `role` begins the line ("experiment", "held out"). With `config_path`,
// every experiment uses that arm instead of its own config_yaml: the file is
// parsed here once for all of them (ExperimentLoadOptions::config), its own
// errors first, naming it.
std::vector<Experiment> LoadExperiments(const std::vector<std::string>& paths,
                                        std::optional<double> noise_deg, double point_noise_mm,
                                        const char* role, const std::string& config_path,
                                        const std::function<void(const std::string&)>& line);

// The backends of the experiment sets (ShareRuns): every rank of an MPI job
// (docs/cluster.md), else `threads` threads. Empty on a rank other than 0
// once it has served rank 0's runs. Reports where the runs go.
std::vector<std::shared_ptr<SimulationBackend>> JobBackends(
    const std::vector<const std::vector<Experiment>*>& sets, const JobRuns& runs,
    const std::function<void(const std::string&)>& line);

// Checkpoints (--resume; docs/cluster.md): OUT/checkpoint.json holds the
// job, the program's version, a digest of what decides the result (the
// options that change it, as text, and the bytes of every input file) and
// the state to resume from.
struct CheckpointKey {
  std::string command;
  std::string digest;
};
CheckpointKey MakeCheckpointKey(const std::string& command, const std::string& options_text,
                                const std::vector<std::string>& input_files);
std::string CheckpointPath(const std::string& out);
// The state saved in OUT. Throws InputError (one line naming the file) when
// there is none, or it is of another command, version, data or options.
nlohmann::json ReadCheckpoint(const std::string& out, const CheckpointKey& key);
// Writes the state atomically (creating OUT); RemoveCheckpoint once the
// job's outputs are written.
void WriteCheckpoint(const std::string& out, const CheckpointKey& key, const nlohmann::json& state);
void RemoveCheckpoint(const std::string& out);

}  // namespace ccsrm::identify
