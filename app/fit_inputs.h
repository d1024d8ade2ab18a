#pragma once
// What `ccsrm identify` and `ccsrm loop` read the same way: the fit's
// parameter options (--free, --params, --set) and the experiment files.
#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/identify/mpi_backend.h"

namespace ccsrm::app {

// Applies --free (when given), --params and --set to options and checks
// the result. Throws InputError naming the option or file.
void ApplyFitOptions(const std::optional<std::string>& free, const std::string& params,
                     const std::vector<std::string>& set, identify::IdentificationOptions* options);

// Loads each experiment and prints one line about it (and the mocap
// pipeline's when it computed the angles). `role` prefixes the line
// ("experiment", "held out"). With `config` (a configuration file), every
// experiment uses that arm instead of its own config_yaml
// (ExperimentLoadOptions::config_yaml).
std::vector<identify::Experiment> LoadExperiments(const std::vector<std::string>& paths,
                                                  double noise_deg, const char* role,
                                                  const std::string& config = "");

// Per-iteration and per-simulation progress lines of a fit.
void PrintFitProgress(identify::IdentificationOptions* options, const std::string& indent);

// The per-simulation progress line ("simulation 3 / 8"), on stderr.
identify::RunFinishedCallback RunProgress();

// --run-timeout (MpiOptions::run_timeout_s), for the commands whose runs go
// to every rank of an MPI job.
void AddRunTimeoutOption(CLI::App* command, double* run_timeout_s);

// The backends of the experiment sets (identify::ShareRuns): every rank of
// an MPI job (docs/cluster.md), else `threads` threads. Empty on a rank other
// than 0 once it has served rank 0's runs: its command is then over. Prints
// where the runs go on stdout.
std::vector<std::shared_ptr<identify::SimulationBackend>> RunBackends(
    const std::vector<const std::vector<identify::Experiment>*>& sets, int threads,
    double run_timeout_s);

// Checkpoints (--resume; docs/cluster.md): OUT/checkpoint.json holds the
// command, the program's version, a digest of what decides the result (the
// options that change it, as text, and the bytes of every input file) and
// the state to resume from.
struct CheckpointKey {
  std::string command;
  std::string digest;
};
CheckpointKey MakeCheckpointKey(const std::string& command, const std::string& options_text,
                                const std::vector<std::string>& input_files);
std::string CheckpointPath(const std::string& out);
// The state saved in OUT, for --resume. Throws InputError (one line naming
// the file) when there is none, or it is of another command, version, data
// or options.
nlohmann::json ReadCheckpoint(const std::string& out, const CheckpointKey& key);
// Writes the state atomically (creating OUT); removes it once the command's
// outputs are written.
void WriteCheckpoint(const std::string& out, const CheckpointKey& key, const nlohmann::json& state);
void RemoveCheckpoint(const std::string& out);

}  // namespace ccsrm::app
