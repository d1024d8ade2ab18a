#include "ccsrm/mocap/recording.h"

#include <cctype>
#include <filesystem>
#include <memory>
#include <utility>
#include <variant>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim_io/experiment_check.h"

namespace ccsrm::mocap {
namespace {

namespace fs = std::filesystem;

bool IsHdf5Name(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".h5" || ext == ".hdf5";
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  return a == b || fs::equivalent(a, b, ec);
}

// What the marker source gave, read once.
struct Recording {
  std::string source;  // names the input in errors and the description
  // The experiment the result goes into: the input experiment itself, or the
  // start of a new one (a run's inputs and source).
  datasets::ExperimentFile experiment;
  bool from_experiment = false;
  // True when `experiment` already holds the inputs of the file `source`
  // (an experiment or run input), so --inputs naming that file reads nothing.
  bool has_file_inputs = false;
  std::string run_config_yaml;  // a run input's configuration text
  MarkerTable table;            // empty until reconstructed, for a reconstruction
  std::vector<double> time;     // empty: frame i at i / rate
};

Recording FromExperiment(datasets::ExperimentFile experiment, const std::string& source) {
  Recording r;
  r.source = source;
  r.table = MarkerTableFromExperiment(experiment);
  r.time = experiment.mocap_time.values;
  r.experiment = std::move(experiment);
  r.from_experiment = true;
  r.has_file_inputs = true;
  return r;
}

Recording ReadRecording(const RecordingRequest& request) {
  if (request.reconstruct) {
    Recording r;
    r.source = request.reconstruction_source.empty() ? "reconstructed markers"
                                                     : request.reconstruction_source;
    return r;
  }
  if (!IsHdf5Name(request.in)) {
    Recording r;
    r.source = request.in;
    r.table = ReadMarkerFile(request.in);
    return r;
  }
  datasets::AnyFile file = datasets::ReadAnyFile(request.in);
  if (auto* experiment = std::get_if<datasets::ExperimentFile>(&file)) {
    return FromExperiment(std::move(*experiment), request.in);
  }
  const datasets::RunFile& run = std::get<datasets::RunFile>(file);  // virtual markers
  Recording r;
  r.source = request.in;
  r.table = MarkerTableFromRun(run, request.in);
  r.time = run.time.values;
  r.experiment.input_time = run.time;
  r.experiment.input_length_change = run.input_length_change;
  r.experiment.source = datasets::ExperimentSource::kGenerated;
  r.has_file_inputs = true;
  r.run_config_yaml = run.config_yaml;
  return r;
}

struct ResolvedLayout {
  MarkerLayout layout;
  std::string config_yaml;  // the text of request.config, when given
  // From config, else the experiment's config_yaml (built by the caller, or
  // here).
  std::shared_ptr<const sim::ArmModel> model;
  std::optional<JointChain> chain;  // with the model
  std::optional<StaticTrialRefinement> static_trial;
};

// RecordingRequest::rigid_bodies documents the order. `known_arm`: the arm of
// the experiment's config_yaml when the caller has built it; else null.
ResolvedLayout ResolveLayout(const RecordingRequest& request, const Recording& recording,
                             std::shared_ptr<const sim::ArmModel> known_arm) {
  ResolvedLayout out;
  const datasets::ExperimentFile* experiment =
      recording.from_experiment ? &recording.experiment : nullptr;
  if (!request.config.empty()) {
    out.config_yaml = ReadTextFile(request.config);
    out.model =
        std::make_shared<sim::ArmModel>(sim::ParseConfig(out.config_yaml, request.config).arm);
  } else if (known_arm) {
    out.model = std::move(known_arm);
  } else if (experiment != nullptr && !experiment->config_yaml.empty()) {
    out.model = std::make_shared<sim::ArmModel>(
        sim::ParseConfig(experiment->config_yaml, recording.source + ": attribute 'config_yaml'")
            .arm);
  }
  if (out.model) out.chain = JointChain::FromModel(*out.model);

  if (!request.rigid_bodies.empty()) {
    out.layout = ReadRigidBodiesFile(request.rigid_bodies);
  } else if (!request.config.empty()) {
    out.layout = DefaultMarkerLayout(*out.model);
  } else if (experiment != nullptr && !experiment->rigid_bodies.empty()) {
    out.layout = LayoutFromExperiment(experiment->rigid_bodies, recording.source);
  } else if (out.model) {
    out.layout = DefaultMarkerLayout(*out.model);
  } else if (experiment != nullptr) {
    ThrowInputError(recording.source, "/mocap/rigid_bodies",
                    "none, and no attribute 'config_yaml' for the default marker layout: give "
                    "--rigid-bodies FILE or --config FILE");
  } else {
    ThrowInputError(recording.source, "rigid bodies",
                    "give --rigid-bodies FILE or --config FILE (the default marker layout)");
  }

  if (!request.static_trial.empty()) {
    if (!out.model) {
      ThrowInputError(request.static_trial, "--static-trial",
                      "needs --config (the arm's kinematics)");
    }
    out.static_trial = RefineFromStaticTrial(
        out.layout, *out.model, ReadMarkerFile(request.static_trial), request.static_trial);
    out.layout = out.static_trial->layout;
  }
  return out;
}

// /input/time and /input/length_change of a run or experiment file, checked
// here, where the file is read (sim_io::CheckInputs: a finite, increasing
// time base, finite lengths and, with an arm known (`model` not null,
// described by `arm_source`), one column per driving cable of that arm).
void CopyInputs(const std::string& path, const sim::ArmModel* model, const std::string& arm_source,
                datasets::ExperimentFile* experiment) {
  const datasets::AnyFile file = datasets::ReadAnyFile(path);
  if (const auto* source = std::get_if<datasets::ExperimentFile>(&file)) {
    sim_io::CheckInputs(*source, path, model, arm_source);
    experiment->input_time = source->input_time;
    experiment->input_length_change = source->input_length_change;
  } else {
    const datasets::RunFile& run = std::get<datasets::RunFile>(file);
    sim_io::CheckInputs(run, path, model, arm_source);
    experiment->input_time = run.time;
    experiment->input_length_change = run.input_length_change;
  }
}

// The pipeline on a recording already read (RecordingRequest: `in` or
// `reconstruct` have been used to make `recording`).
ProcessedRecording Process(const RecordingRequest& request, Recording recording,
                           std::shared_ptr<const sim::ArmModel> known_arm = nullptr) {
  ProcessedRecording out;
  ResolvedLayout layout = ResolveLayout(request, recording, std::move(known_arm));
  out.static_trial = std::move(layout.static_trial);
  datasets::ExperimentFile& experiment = recording.experiment;
  if (!request.inputs.empty() &&
      !(recording.has_file_inputs && !request.in.empty() && SameFile(request.inputs, request.in))) {
    // Read and checked first, before markers are reconstructed or processed:
    // against the arm the experiment is written with (--config, else the
    // input's own config_yaml: an experiment's, or a run's, which the layout
    // may not have needed).
    const std::string arm_source =
        !request.config.empty() ? request.config : recording.source + " (its config_yaml)";
    const std::string& written_yaml =
        recording.from_experiment
            ? experiment.config_yaml
            : (!layout.config_yaml.empty() ? layout.config_yaml : recording.run_config_yaml);
    const sim::ArmModel* arm = layout.model.get();
    std::unique_ptr<sim::ArmModel> own_arm;
    if (arm == nullptr && !written_yaml.empty()) {
      own_arm = std::make_unique<sim::ArmModel>(
          sim::ParseConfig(written_yaml, recording.source + ": attribute 'config_yaml'").arm);
      arm = own_arm.get();
    }
    CopyInputs(request.inputs, arm, arm_source, &experiment);
  }
  if (request.reconstruct) {
    ReconstructedMarkers reconstructed = request.reconstruct(layout.layout, layout.model.get());
    recording.table = std::move(reconstructed.markers);
    out.reconstruction_report = std::move(reconstructed.report);
  }
  out.result = ProcessMarkers(recording.table, recording.time, layout.layout, request.processing,
                              recording.source, layout.chain ? &*layout.chain : nullptr);
  const ProcessingResult& result = out.result;

  if (!recording.from_experiment) {
    experiment.name =
        !request.name.empty() ? request.name : fs::path(recording.source).stem().string();
    experiment.description = "markers of " + fs::path(recording.source).filename().string() + " (" +
                             recording.table.format + "), processed by ccsrm mocap process";
    experiment.config_yaml =
        !layout.config_yaml.empty() ? layout.config_yaml : recording.run_config_yaml;
    experiment.mocap_time = datasets::Array({result.time.size()});
    experiment.mocap_time.values = result.time;
    experiment.mocap_markers = result.raw_markers;
    experiment.marker_names = result.marker_names;
    if (experiment.input_time.rows() == 0) {
      // No actuator record: one sample at the start with no cable columns.
      experiment.input_time = datasets::Array({1}, result.time.front());
      experiment.input_length_change = datasets::Array({1, 0});
    }
  }
  experiment.rigid_bodies = ToExperimentRigidBodies(layout.layout);
  experiment.mocap_quality.clear();
  experiment.mocap_quality_units.clear();
  experiment.created.clear();
  StoreInExperiment(result, &experiment);
  datasets::ValidateExperimentFile(experiment, recording.source);
  out.experiment = std::move(experiment);
  return out;
}

}  // namespace

bool RecordingRequest::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& reason) {
    if (error != nullptr) *error = reason;
    return false;
  };
  if (in.empty() && !reconstruct) {
    return fail("no marker source: give `in` (a marker file) or `reconstruct`");
  }
  if (!in.empty() && reconstruct) {
    return fail("two marker sources: give `in` (a marker file) or `reconstruct`, not both");
  }
  if (reconstruct && rigid_bodies.empty() && config.empty()) {
    return fail("`reconstruct` needs `rigid_bodies` or `config` (the markers to label)");
  }
  std::string processing_error;
  if (!processing.IsValid(&processing_error)) return fail("processing: " + processing_error);
  return true;
}

ProcessedRecording ProcessRecording(const RecordingRequest& request) {
  std::string error;
  if (!request.IsValid(&error)) ThrowInputError("mocap recording request", "", error);
  return Process(request, ReadRecording(request));
}

ProcessedRecording AddMeasuredJointAngles(const datasets::ExperimentFile& experiment,
                                          const std::string& source,
                                          const ProcessingOptions& options,
                                          std::shared_ptr<const sim::ArmModel> arm) {
  const std::string name = source.empty() ? "experiment" : source;
  RecordingRequest request;
  request.in = name;  // names the input; nothing is read
  request.processing = options;
  std::string error;
  if (!request.IsValid(&error)) ThrowInputError(name, "", error);
  datasets::ValidateExperimentFile(experiment, name);
  return Process(request, FromExperiment(experiment, name), std::move(arm));
}

}  // namespace ccsrm::mocap
