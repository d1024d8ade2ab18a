// What every job of job.h does alike: its output folder's kind, loading
// experiments, where the runs go, checkpoints.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/digest.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "ccsrm/identify/job.h"
#include "ccsrm/sim/config.h"
#include "job_stages.h"
#include "text.h"

namespace ccsrm::identify {

namespace fs = std::filesystem;

namespace {

constexpr const char* kCheckpointSchema = "ccsrm-checkpoint/1";

// A JSON file `name` inside `folder` whose "schema" is `schema`.
bool FolderJsonHasSchema(const std::string& folder, const std::string& name,
                         const std::string& schema) {
  std::ifstream in(fs::path(folder) / name);
  if (!in) return false;
  const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return json.is_object() && json.contains("schema") && json["schema"] == schema;
}

// The folder of `file` (schema `schema`), or one a stopped job left its
// checkpoint in (--resume) when `resumable`.
OutputKind JobFolder(const std::string& description, const std::string& file,
                     const std::string& schema, bool resumable) {
  OutputKind kind{
      description, true, [=](const std::string& p) {
        return FolderJsonHasSchema(p, file, schema) ||
               (resumable && FolderJsonHasSchema(p, "checkpoint.json", kCheckpointSchema));
      }};
  if (resumable) kind.own_files = {"checkpoint.json", "runs.journal"};
  return kind;
}

}  // namespace

OutputKind FitFolderOutput() {
  return JobFolder("ccsrm fit folder (fit.json, ccsrm-fit/1)", "fit.json", "ccsrm-fit/1", true);
}

OutputKind LoopFolderOutput() {
  return JobFolder("ccsrm loop folder (loop.json, ccsrm-loop/1)", "loop.json", "ccsrm-loop/1",
                   true);
}

OutputKind PredictionFolderOutput() {
  return JobFolder("ccsrm prediction folder (pred.json, ccsrm-prediction/1)", "pred.json",
                   "ccsrm-prediction/1", false);
}

OutputKind DesignFolderOutput() {
  return JobFolder("ccsrm design folder (design.json, ccsrm-design/1)", "design.json",
                   "ccsrm-design/1", true);
}

namespace internal {

namespace {

// The same file by two names (a link, "./a.h5"), or the same name twice.
bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec) ||
         fs::absolute(a, ec).lexically_normal() == fs::absolute(b, ec).lexically_normal();
}

}  // namespace

void RefuseRepeatedFiles(const std::vector<std::string>& files, const std::string& option,
                         const std::vector<std::string>& others, const std::string& others_option) {
  for (std::size_t i = 0; i < files.size(); ++i) {
    for (std::size_t j = i + 1; j < files.size(); ++j) {
      if (SameFile(files[i], files[j])) {
        ThrowInputError(files[j], option,
                        "given twice (as '" + files[i] + "'): an experiment counts once");
      }
    }
    for (const std::string& other : others) {
      if (SameFile(files[i], other)) {
        ThrowInputError(other, others_option,
                        "is also in " + option + ": a held-out experiment must not be fitted");
      }
    }
  }
}

void ApplyFitJob(const FitJobOptions& job, IdentificationOptions* fit) {
  if (job.data.empty()) ThrowInputError("--data", "", "give at least one experiment file");
  RefuseRepeatedFiles(job.data, "--data", {}, "");
  // The library's 0 (statistics at the start values, which design uses) is
  // no fit: a job that asked for one would report "converged" unmoved.
  if (job.max_iterations < 1) {
    ThrowInputError("--max-iterations", "",
                    "is " + std::to_string(job.max_iterations) +
                        ": a fit takes at least 1 iteration (`ccsrm predict` evaluates values "
                        "without fitting)");
  }
  fit->threads = job.runs.threads;
  fit->max_iterations = job.max_iterations;
  const FitParameterChoice& p = job.parameters;
  ApplyFitParameters(p.free ? &*p.free : nullptr, p.params_path, p.values, fit);
}

}  // namespace internal

std::vector<Experiment> LoadExperiments(const std::vector<std::string>& paths,
                                        std::optional<double> noise_deg, double point_noise_mm,
                                        const char* role, const std::string& config_path,
                                        const std::function<void(const std::string&)>& line) {
  ExperimentLoadOptions load;
  load.noise_deg = noise_deg;
  load.point_noise_mm = point_noise_mm;
  // The configuration given is parsed here, once for every experiment (its
  // own errors first, naming it).
  if (!config_path.empty())
    load.config = std::make_shared<const sim::Config>(sim::LoadConfig(config_path));
  std::vector<Experiment> experiments;
  for (const std::string& path : paths) {
    experiments.push_back(LoadExperiment(path, load));
    const Experiment& e = experiments.back();
    if (!line) continue;
    if (e.angles_from_pipeline) line("mocap " + path + ": " + e.pipeline_report + "\n");
    if (!e.tracked_points.empty()) {
      line(
          Format("%s %s (%s): %zu frames, %.4g s, %zu measured coordinates of %zu tracked "
                 "point%s, noise %.3g mm%s\n",
                 role, e.name.c_str(), path.c_str(), e.frame_time_s.size(), e.duration_s(),
                 e.measured_samples, e.tracked_points.size(),
                 e.tracked_points.size() == 1 ? "" : "s", e.point_noise_mm,
                 e.point_placement == PointPlacement::kFittedRigidMotion
                     ? " (in the capture frame: each run placed by its best rigid motion)"
                     : ""));
      continue;
    }
    double noise = 0.0;
    for (double s : e.noise_deg) noise += s / static_cast<double>(e.noise_deg.size());
    line(Format("%s %s (%s): %zu frames, %.4g s, %zu measured angles, noise %.4f deg (%s)%s\n",
                role, e.name.c_str(), path.c_str(), e.frame_time_s.size(), e.duration_s(),
                e.measured_samples, noise, e.noise_source.c_str(),
                e.angles_from_pipeline
                    ? "; no measured joint angles in the file: computed by the mocap "
                      "pipeline with default settings"
                    : ""));
  }
  return experiments;
}

std::vector<std::shared_ptr<SimulationBackend>> JobBackends(
    const std::vector<const std::vector<Experiment>*>& sets, const JobRuns& runs,
    const std::function<void(const std::string&)>& line) {
  MpiOptions mpi;
  mpi.threads = runs.threads;
  mpi.run_timeout_s = runs.run_timeout_s;
  std::vector<std::shared_ptr<SimulationBackend>> backends = ShareRuns(sets, mpi);
  if (!backends.empty() && MpiRanks() > 1 && line) {
    line(Format("runs on %d MPI ranks, %d at a time\n", MpiRanks(),
                backends.front()->parallelism()));
  }
  return backends;
}

CheckpointKey MakeCheckpointKey(const std::string& command, const std::string& options_text,
                                const std::vector<std::string>& input_files) {
  Fnv1aDigest digest;
  for (const std::string& part : {std::string(kVersion), command, options_text}) {
    digest.Add(part.data(), part.size() + 1);  // with its terminator: parts stay apart
  }
  for (const std::string& file : input_files) {
    if (file.empty()) continue;
    std::ifstream in(file, std::ios::binary);
    char buffer[1 << 16];
    while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) {
      digest.Add(buffer, static_cast<std::size_t>(in.gcount()));
    }
  }
  return {command, digest.Hex()};
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
  if (json.is_discarded()) {
    ThrowInputError(path, "--resume",
                    "corrupt: not JSON (cut short by a full disk?); nothing to resume (remove the "
                    "folder, or run without --resume into a new one)");
  }
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

}  // namespace ccsrm::identify
