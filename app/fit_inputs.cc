#include "fit_inputs.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
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

namespace {

constexpr const char* kCheckpointSchema = "ccsrm-checkpoint/1";

// 64-bit FNV-1a: a change of any byte changes the digest (not a defence
// against forgery; it tells runs apart).
void Digest(const char* data, std::size_t n, std::uint64_t* h) {
  for (std::size_t i = 0; i < n; ++i) {
    *h ^= static_cast<unsigned char>(data[i]);
    *h *= 1099511628211ULL;
  }
}

}  // namespace

CheckpointKey MakeCheckpointKey(const std::string& command, const std::string& options_text,
                                const std::vector<std::string>& input_files) {
  std::uint64_t h = 14695981039346656037ULL;
  for (const std::string& part : {std::string(kVersion), command, options_text}) {
    Digest(part.data(), part.size() + 1, &h);  // with its terminator: parts stay apart
  }
  for (const std::string& file : input_files) {
    if (file.empty()) continue;
    std::ifstream in(file, std::ios::binary);
    char buffer[1 << 16];
    while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) {
      Digest(buffer, static_cast<std::size_t>(in.gcount()), &h);
    }
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(h));
  return {command, text};
}

std::string CheckpointPath(const std::string& out) {
  return (fs::path(out) / "checkpoint.json").string();
}

nlohmann::json ReadCheckpoint(const std::string& out, const CheckpointKey& key) {
  const std::string path = CheckpointPath(out);
  if (!fs::exists(path)) {
    ThrowInputError(path, "--resume",
                    "no checkpoint here: nothing to resume (run without --resume)");
  }
  const nlohmann::json json = nlohmann::json::parse(ReadTextFile(path), nullptr, false);
  if (!json.is_object() || json.value("schema", "") != kCheckpointSchema) {
    ThrowInputError(path, "schema", std::string("not a ") + kCheckpointSchema + " file");
  }
  const std::string refuse = "; refusing to resume (run without --resume to start over)";
  if (json.value("command", "") != key.command) {
    ThrowInputError(path, "command",
                    "the checkpoint is of `ccsrm " + json.value("command", "") + "`" + refuse);
  }
  if (json.value("version", "") != kVersion) {
    ThrowInputError(
        path, "version",
        "written by ccsrm " + json.value("version", "") + ", this is " + kVersion + refuse);
  }
  if (json.value("inputs_digest", "") != key.digest) {
    ThrowInputError(path, "inputs_digest",
                    "the checkpoint is of other data or options (digest " +
                        json.value("inputs_digest", "") + ", these give " + key.digest + ")" +
                        refuse);
  }
  return json.at("state");
}

void WriteCheckpoint(const std::string& out, const CheckpointKey& key,
                     const nlohmann::json& state) {
  fs::create_directories(out);
  const nlohmann::json json = {{"schema", kCheckpointSchema},
                               {"command", key.command},
                               {"version", kVersion},
                               {"inputs_digest", key.digest},
                               {"state", state}};
  WriteTextFileAtomically(CheckpointPath(out), json.dump() + "\n");
}

void RemoveCheckpoint(const std::string& out) {
  std::error_code ignored;
  fs::remove(CheckpointPath(out), ignored);
}

}  // namespace ccsrm::app
