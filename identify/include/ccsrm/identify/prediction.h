#pragma once
// Prediction (issue 25): a fitted model run on recordings it was not fitted
// to. Each recording is simulated from its own /input/length_change with
// the model's parameters (its effects included) over the recording's
// nominal configuration, and compared at its own mocap frames exactly as
// identification compares: the simulated angles as motion capture records
// them (sim::RecordedJointAngles), through the measurement's gaps and
// low-pass (Experiment::AsMeasured), residual = predicted - measured,
// weighted by the recording's measurement noise (ExperimentLoadOptions).
// At the noise floor the weighted RMS is about 1; where the model lacks
// something the channels it touches stand above it.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/identify/adequacy.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {

// The model a prediction runs: parameter values by name, set over each
// recording's nominal configuration the way a fit sets its values.
struct PredictionModel {
  std::string source;  // the file the values were read from (messages, pred.json)
  std::string kind;    // "ccsrm-fit/1" (a fit of identify or loop) or "parameter file"
  // Every value the source gives, by SPEC 6 name or "<effect>.<parameter>";
  // an effect parameter switches its effect on (a fit.json lists every
  // parameter of each effect its model had on).
  std::map<std::string, double> values;
  std::vector<std::string> free;  // the fit's free parameters, when the source is a fit
  // The arm the fit was made on, when the source records it: a recording
  // of another arm is refused. fit.json's `arm` (joints and driving cables),
  // else the number of joints of its error table; unset for a parameter file.
  std::optional<sim::ArmSize> arm;
  // Effects switched on over the values, in order: each the YAML of
  // sim::ApplyEffectsYaml and the file it came from (a truth file's
  // `effects:`, then `ccsrm predict --effects FILE`). Default: none.
  struct Effects {
    std::string yaml;
    std::string file;
  };
  std::vector<Effects> effects;
  // The capture frame's placement the fit found (FitFile::capture_placement):
  // a recording of tracked points in the capture frame is placed by it, so
  // that its errors are a prediction's, not a fit's of six more values.
  // Unset (a parameter file, a fit of angles): each such recording is placed
  // by its own best rigid motion, and the report says so.
  std::optional<RigidPlacement> capture_placement;
};

// Reads the model from `path`: a fit.json (schema ccsrm-fit/1, as `ccsrm
// identify` writes it and `ccsrm loop` writes its final model's in
// final/fit.json), a fit folder (its fit.json), a loop folder or its
// loop.json (the final model: final/fit.json beside it), or a parameter
// YAML file in the format of `ccsrm identify --params` (`name: value` or
// `name: {value, free, bounds}`; free flags and bounds mean nothing here), or
// a truth file of `ccsrm generate` (its `parameters:`, and its `effects:`
// into `effects`). Throws InputError "<file>: <key>: <problem>":
// a missing file, JSON that does not parse, another schema, a parameter
// entry without a finite value, an unknown parameter name or a value out
// of its bounds.
PredictionModel LoadPredictionModel(const std::string& path);

struct PredictionOptions {
  // Simulations at a time on this machine (ThreadBackend). Default: every core.
  int threads = DefaultThreads();
  // Another backend (null: threads on this machine). It must have been given
  // the same recordings, in the same order.
  std::shared_ptr<SimulationBackend> backend;
  // The rule of a channel above the noise (AssessModelAdequacy; defaults
  // kAboveNoiseRatio and kAboveNoiseSignificance, as identification's).
  double above_noise_ratio = kAboveNoiseRatio;
  double significance = kAboveNoiseSignificance;
  // Called after each finished run, one call at a time; may be empty.
  RunFinishedCallback on_run;

  // False with the reason: threads < 1, above_noise_ratio not > 0,
  // significance outside (0, 1).
  bool IsValid(std::string* error) const;
};

// The errors of predicted angles against measured ones, per joint and axis
// ([joint][axis], axis 0 θx, 1 θy) and overall.
struct PredictionErrors {
  // RMS, motion and fit percent as identification reports them
  // (AngleErrors): the same numbers a fit table shows.
  ChannelErrors channels;
  std::vector<std::array<double, 2>> max_abs_deg;  // largest |predicted - measured|
  std::vector<double> noise_deg;                   // per joint (mean over the recordings)
  double max_abs_deg_overall = 0.0;
  // sqrt(mean of ((predicted - measured) / noise)^2) over every measured
  // sample (angles and tracked points' coordinates): identification's
  // weighted residual, 1 at the noise floor.
  double weighted_rms = 0.0;
};

// The errors of `predicted` (one matrix per recording, laid out as
// Experiment::measured) against the recordings' measured angles.
PredictionErrors ComputePredictionErrors(const std::vector<const Experiment*>& recordings,
                                         const std::vector<const Eigen::MatrixXd*>& predicted);

struct RecordingPrediction {
  std::string name;
  std::string path;
  bool angles_from_pipeline = false;
  std::string noise_source;
  sim::ArmParameters parameters;  // of the run
  sim::SimulationResult run;      // trajectory at the recording's sample times
  Eigen::MatrixXd predicted_rad;  // as Experiment::measured, made comparable (AsMeasured)
  PredictionErrors errors;
  // Of a recording of tracked points: their errors (the publishing
  // project's metric among them: the RMS with the mean offset removed), and
  // where the run was placed when the points were recorded in the capture
  // frame (by the rigid motion that fits this recording best).
  std::vector<TrackedPoint> tracked_points;
  TrackedPointErrors points;
  bool placed_in_capture_frame = false;
  bool placement_from_fit = false;  // else fitted to this recording
  RigidPlacement placement;
};

struct PredictionSummary {
  PredictionModel model;
  std::vector<std::string> effects;  // on in the predicted model
  std::vector<RecordingPrediction> recordings;
  PredictionErrors errors;  // every recording together
  // Whether the model explains the recordings: the channels above the
  // noise, and the verdict that heads the report (adequacy.h).
  ModelAdequacy adequacy;
  int threads = 0;
  std::int64_t simulations = 0;
  double wall_time_s = 0.0;
  // Every run completed; else the first failure, "<recording>: <message>".
  bool completed = true;
  std::string message;

  std::string BriefReport() const;
  std::string FullReport() const;
};

// Runs every recording with the model and compares. Throws InputError before
// any simulation when the options are invalid, there is no recording, the
// model names a parameter a recording's arm does not have or a value out of
// bounds (naming the model's file), the model's arm differs from a
// recording's, or the effects file is bad. A run that diverges is reported
// in the summary (completed, message), not thrown.
PredictionSummary Predict(const std::vector<Experiment>& recordings, const PredictionModel& model,
                          const PredictionOptions& options);

// pred.json: schema ccsrm-prediction/1 (identify/README.md).
nlohmann::json ToJson(const PredictionSummary& summary);

// Writes a prediction folder atomically (replacing an existing one whole):
// pred.json; per recording <name>.pred.h5 (ccsrm-run/1 of the predicted run
// at the measured frames) and <name>.angles.csv (time, then measured,
// predicted and residual θx, θy of every joint, deg; residual = predicted -
// measured). Returns the paths written.
std::vector<std::string> WritePredictionDirectory(const PredictionSummary& summary,
                                                  const std::vector<Experiment>& recordings,
                                                  const std::string& directory);

}  // namespace ccsrm::identify
