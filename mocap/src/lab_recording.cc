#include "ccsrm/mocap/lab_recording.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/mocap/actuator_log.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/sim/config.h"
#include "text_table.h"

namespace ccsrm::mocap {
namespace {

using internal::FormatNumber;

namespace fs = std::filesystem;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The analog channel holding the trigger pulse (LabRecordingRequest says
// which is taken by default).
std::size_t TriggerChannel(const C3dAnalog& analog, const std::string& wanted,
                           const std::string& file) {
  std::string labels;
  for (const std::string& l : analog.labels) labels += (labels.empty() ? "" : ", ") + l;
  if (analog.channels() == 0) {
    ThrowInputError(file, "ANALOG",
                    "no analog channel: --sync trigger needs the trigger pulse "
                    "on one (or use --sync estimate or offset=S)");
  }
  if (!wanted.empty()) {
    if (const auto c = analog.index_of(wanted)) return *c;
    ThrowInputError(file, "--trigger-channel",
                    "no analog channel '" + wanted + "' (the file has " + labels + ")");
  }
  if (analog.channels() == 1) return 0;
  for (std::size_t c = 0; c < analog.channels(); ++c) {
    const std::string l = Lower(analog.labels[c]);
    if (l == "trigger" || l == "sync") return c;
  }
  ThrowInputError(file, "--trigger-channel",
                  "several analog channels (" + labels + "): name the trigger's");
}

// One time stamp's jitter [s]: the robust scatter (1.4826 × the median
// absolute deviation) of the log's steps about their median, over √2.
double StampJitter(const Eigen::VectorXd& time_s) {
  const Eigen::Index n = time_s.size();
  if (n < 3) return 0.0;
  std::vector<double> steps(static_cast<std::size_t>(n - 1));
  for (Eigen::Index i = 1; i < n; ++i) steps[i - 1] = time_s[i] - time_s[i - 1];
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  const double middle = median(steps);
  for (double& s : steps) s = std::abs(s - middle);
  return 1.4826 * median(steps) / std::sqrt(2.0);
}

// --sync trigger: the edges of the C3D analog channel `channel` matched to
// those of the log's trigger column.
ClockFit AlignByTriggerChannel(const C3dAnalog& analog, std::size_t channel,
                               const std::vector<double>& mocap_time, const ActuatorLog& log,
                               const ActuatorMap& map, const LabRecordingRequest& request) {
  Eigen::VectorXd t(static_cast<Eigen::Index>(analog.sample_count));
  Eigen::VectorXd v(static_cast<Eigen::Index>(analog.sample_count));
  for (std::size_t s = 0; s < analog.sample_count; ++s) {
    // Analog sample s of frame f = s / samples_per_frame lies s mod
    // samples_per_frame sub-steps after the frame's time.
    t[static_cast<Eigen::Index>(s)] = mocap_time.front() + analog.time_s(s);
    v[static_cast<Eigen::Index>(s)] = analog.value(s, channel);
  }
  const std::vector<double> mocap_edges = FindEdges(t, v, request.mocap_edges);
  EdgeOptions log_edges_options;
  log_edges_options.threshold = map.trigger->threshold;
  log_edges_options.rising = map.trigger->polarity == "rising";
  log_edges_options.interpolate = false;  // the controller set its output at that tick
  log_edges_options.min_separation_s = request.mocap_edges.min_separation_s;
  const std::vector<double> log_edges = FindEdges(log.time_s, log.trigger, log_edges_options);
  TriggerAlignmentOptions options = request.trigger;
  // Quantisation of a crossing to one sample: period / √12.
  if (options.mocap_edge_sigma_s <= 0.0) {
    options.mocap_edge_sigma_s = 1.0 / (analog.rate_hz * std::sqrt(12.0));
  }
  // The log's edges are its ticks (the controller raised its output
  // then): their error is the stamps' jitter, measured on the log
  // itself from the scatter of its steps (a step is the difference of
  // two stamps: √2 × one stamp's jitter).
  if (options.log_edge_sigma_s <= 0.0) {
    options.log_edge_sigma_s = StampJitter(log.time_s);
  }
  ClockFit clock =
      AlignByTrigger(mocap_edges, log_edges, options, request.markers + " + " + request.actuators);
  clock.note = "channel '" + analog.labels[channel] + "': " + clock.note;
  return clock;
}

// The joint angles as a second witness of an alignment made without them:
// where they put the log at the middle of the recording, against
// out->clock. Sets out->misaligned and out->kinematic_check.
void CheckAlignmentKinematically(const sim::ArmModel& model, const std::vector<double>& mocap_time,
                                 const std::vector<double>& angles, const ActuatorLog& log,
                                 const LabRecordingRequest& request, AssembledRecording* out) {
  const double t_mid = 0.5 * (mocap_time.front() + mocap_time.back());
  const double frame_s = (mocap_time.back() - mocap_time.front()) /
                         static_cast<double>(std::max<std::size_t>(1, mocap_time.size() - 1));
  // Within 1 s of the alignment used (ten times the largest lag seen on
  // the generated arms): the check costs a fraction of a full search.
  KinematicAlignmentOptions window = request.estimate;
  window.estimate_drift = false;
  window.search_center_s = out->clock.LogTime(t_mid) - t_mid;
  window.search_half_width_s = 1.0;
  try {
    const ClockFit kinematic =
        AlignByKinematics(model, mocap_time, angles, log.time_s, log.length_change_m, window,
                          request.markers + " + " + request.actuators);
    const double difference = kinematic.LogTime(t_mid) - out->clock.LogTime(t_mid);
    const double sigma = std::hypot(kinematic.offset_sigma_s, out->clock.offset_sigma_s);
    const double limit = std::max(4.0 * sigma, 2.0 * frame_s);
    out->misaligned = std::abs(difference) > limit;
    out->kinematic_check =
        "kinematic check: the joint angles put the log " + FormatNumber("%+.1f", difference * 1e3) +
        " ms from this alignment (± " + FormatNumber("%.2g", sigma * 1e3) + " ms)" +
        (out->misaligned
             ? ", more than the " + FormatNumber("%.3g", limit * 1e3) +
                   " ms a quasi-static arm allows: check the trigger or the offset (or the "
                   "arm lags its inputs: friction, elasticity; --sync estimate, which simulates "
                   "the arm, tells them apart)"
             : ": consistent");
  } catch (const InputError& e) {
    out->kinematic_check = std::string("kinematic check not possible: ") + e.what();
  }
}

}  // namespace

bool LabRecordingRequest::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  if (markers.empty()) return fail("--markers: a marker file is required");
  if (actuators.empty()) return fail("--actuators: the actuators' log is required");
  if (actuator_map.empty()) return fail("--actuator-map: the log's map is required");
  if (config.empty()) return fail("--config: the arm's configuration is required");
  if (!std::isfinite(clock_offset_s)) return fail("--sync offset=S: S must be finite");
  if (!std::isfinite(clock_drift_ppm) || std::abs(clock_drift_ppm) >= 1e5) {
    return fail("--clock-drift-ppm: expected a finite rate difference below 1e5 ppm");
  }
  if (!params.empty() && sync != ClockSync::kEstimate) {
    return fail("--params: only with --sync estimate (the prior of its simulation)");
  }
  if (clock_drift_ppm != 0.0 && sync != ClockSync::kOffset) {
    return fail("--clock-drift-ppm: only with --sync offset=S (the other methods find it)");
  }
  if (!(mocap_edges.min_separation_s >= 0.0)) {
    return fail("trigger: min_separation_s must be >= 0");
  }
  if (!std::isnan(mocap_edges.threshold) && !std::isfinite(mocap_edges.threshold)) {
    return fail("--trigger-threshold: expected a finite level");
  }
  if (!(trigger.max_drift > 0.0)) return fail("trigger: max_drift must be > 0");
  if (!(estimate.grid_step_s >= 0.0) || !(estimate.ambiguity_separation_s >= 0.0) ||
      !(estimate.ambiguity_chi2 > 0.0) || !(estimate.max_drift > 0.0) ||
      !(estimate.drift_step > 0.0) || !(estimate.max_drift / estimate.drift_step <= 1e4) ||
      !(estimate.coarse_step_s >= 0.0)) {
    return fail(
        "estimate: grid steps and separation must be >= 0, chi2, max drift and drift step > 0, "
        "at most 1e4 drift steps each way");
  }
  return processing.IsValid(error);
}

std::string AssembledRecording::Report() const {
  std::string out = "actuator log: " + log_summary + "\n";
  out += "clock alignment (" + clock.method +
         "): log time = " + FormatNumber("%.6f", clock.offset_s) + " s + (1 + " +
         FormatNumber("%.2f", clock.drift * 1e6) + " ppm) × mocap time; offset ± " +
         FormatNumber("%.3g", clock.offset_sigma_s * 1e3) + " ms";
  if (clock.drift_sigma > 0.0)
    out += ", drift ± " + FormatNumber("%.3g", clock.drift_sigma * 1e6) + " ppm";
  out += "\n  " + clock.note + "\n";
  if (!kinematic_check.empty()) {
    out += std::string(misaligned ? "warning: " : "  ") + kinematic_check + "\n";
  }
  const datasets::ExperimentFile& e = processed.experiment;
  out += "inputs: " + std::to_string(e.input_length_change.shape[1]) + " cable(s) resampled onto " +
         std::to_string(e.input_time.size()) + " mocap frames (linear interpolation)\n";
  return out;
}

AssembledRecording AssembleLabRecording(const LabRecordingRequest& request) {
  std::string error;
  if (!request.IsValid(&error)) ThrowInputError("dataset assemble", "options", error);
  // The small files first: a bad map or log is reported before any
  // processing.
  const ActuatorMap map = ReadActuatorMap(request.actuator_map);
  const ActuatorLog log = ReadActuatorLog(request.actuators, map, request.actuator_map);
  sim::Config config = sim::LoadConfig(request.config);
  if (!request.params.empty()) {
    sim::ApplyParameterYaml(ReadTextFile(request.params), request.params, &config.parameters);
  }
  const sim::ArmModel model(config.arm);
  CheckActuatorLogOnArm(log, map, request.actuator_map, model, request.config);
  if (request.sync == ClockSync::kTrigger && log.trigger.size() == 0) {
    ThrowInputError(request.actuator_map, "trigger",
                    "missing: --sync trigger needs the log's trigger column");
  }

  // The markers, read once (with the analog channels of a C3D file).
  C3dRecording recording = ReadMarkerFileWithAnalog(request.markers);
  const C3dAnalog analog = std::move(recording.analog);
  // The trigger's channel is found before the (slower) processing.
  const std::size_t trigger_channel =
      request.sync == ClockSync::kTrigger
          ? TriggerChannel(analog, request.trigger_channel, request.markers)
          : 0;
  RecordingRequest pipeline;
  pipeline.reconstruct = [table = std::move(recording.markers)](const MarkerLayout&,
                                                                const sim::ArmModel*) {
    return ReconstructedMarkers{table, ""};
  };
  pipeline.reconstruction_source = request.markers;
  pipeline.rigid_bodies = request.rigid_bodies;
  pipeline.config = request.config;
  pipeline.static_trial = request.static_trial;
  pipeline.name = request.name.empty() ? fs::path(request.markers).stem().string() : request.name;
  pipeline.processing = request.processing;

  AssembledRecording out;
  out.processed = ProcessRecording(pipeline);
  datasets::ExperimentFile& experiment = out.processed.experiment;
  const std::vector<double>& mocap_time = experiment.mocap_time.values;

  const Eigen::Index n = log.time_s.size();
  const double log_step = (log.time_s[n - 1] - log.time_s[0]) / static_cast<double>(n - 1);
  out.log_summary = request.actuators + ": " + std::to_string(n) + " samples, " +
                    std::to_string(log.length_change_m.cols()) + " cable(s), " +
                    FormatNumber("%.6g", log.time_s[0]) + " to " +
                    FormatNumber("%.6g", log.time_s[n - 1]) + " s on its clock (mean step " +
                    FormatNumber("%.3g", log_step * 1e3) + " ms)";

  switch (request.sync) {
    case ClockSync::kOffset:
      out.clock.method = "offset";
      out.clock.offset_s = request.clock_offset_s;
      out.clock.drift = request.clock_drift_ppm * 1e-6;
      out.clock.note = "given (--sync offset=S)";
      break;
    case ClockSync::kTrigger:
      out.clock = AlignByTriggerChannel(analog, trigger_channel, mocap_time, log, map, request);
      break;
    case ClockSync::kEstimate:
    case ClockSync::kEstimateKinematic: {
      if (!experiment.measured_joint_angles) {
        ThrowInputError(request.markers, "/measured/joint_angles",
                        "none: --sync estimate needs the joint angles");
      }
      const std::string source = request.markers + " + " + request.actuators;
      out.clock =
          request.sync == ClockSync::kEstimate
              ? AlignBySimulation(model, config.parameters, config.solver, mocap_time,
                                  experiment.measured_joint_angles->values, log.time_s,
                                  log.length_change_m, request.estimate, source)
              : AlignByKinematics(model, mocap_time, experiment.measured_joint_angles->values,
                                  log.time_s, log.length_change_m, request.estimate, source);
      break;
    }
  }

  const bool estimated =
      request.sync == ClockSync::kEstimate || request.sync == ClockSync::kEstimateKinematic;
  if (!estimated && experiment.measured_joint_angles) {
    CheckAlignmentKinematically(model, mocap_time, experiment.measured_joint_angles->values, log,
                                request, &out);
  }

  const Eigen::MatrixXd lengths = ResampleOntoMocapTimes(out.clock, mocap_time, log.time_s,
                                                         log.length_change_m, request.actuators);
  experiment.input_time = experiment.mocap_time;
  experiment.input_length_change =
      datasets::Array({mocap_time.size(), static_cast<std::size_t>(lengths.cols())});
  for (std::size_t f = 0; f < mocap_time.size(); ++f) {
    for (Eigen::Index c = 0; c < lengths.cols(); ++c) {
      experiment.input_length_change.values[f * lengths.cols() + c] =
          lengths(static_cast<Eigen::Index>(f), c);
    }
  }
  experiment.source = datasets::ExperimentSource::kRecorded;
  experiment.description = "markers of " + fs::path(request.markers).filename().string() +
                           " and actuator log " + fs::path(request.actuators).filename().string() +
                           ", assembled by ccsrm dataset assemble";
  datasets::ClockAlignment alignment;
  alignment.method = out.clock.method;
  alignment.actuator_log = fs::path(request.actuators).filename().string();
  alignment.offset_s = out.clock.offset_s;
  alignment.offset_uncertainty_s = out.clock.offset_sigma_s;
  alignment.drift_ppm = out.clock.drift * 1e6;
  alignment.drift_uncertainty_ppm = out.clock.drift_sigma * 1e6;
  alignment.note = out.clock.note + (out.kinematic_check.empty() ? "" : "; " + out.kinematic_check);
  experiment.clock_alignment = alignment;
  datasets::ValidateExperimentFile(experiment, request.markers);
  return out;
}

}  // namespace ccsrm::mocap
