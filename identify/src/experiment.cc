#include "ccsrm/identify/experiment.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "ccsrm/common/autocorrelation.h"
#include "ccsrm/common/error.h"
#include "ccsrm/mocap/recording.h"
#include "ccsrm/mocap/signal.h"
#include "ccsrm/sim/simulator.h"
#include "ccsrm/sim_io/experiment_check.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

// The noise profile of the experiment's recorded low-pass, if it has one.
std::optional<mocap::ZeroLagNoiseGain> LowPassNoiseGain(const Experiment& e) {
  if (!e.low_pass) return std::nullopt;
  const Experiment::LowPass& f = *e.low_pass;
  return mocap::ZeroLagNoiseGain(mocap::DesignButterworthLowPass(f.order, f.cutoff_hz, f.rate_hz),
                                 f.cutoff_hz, f.rate_hz,
                                 static_cast<std::size_t>(f.min_run_frames));
}

// e->relative_noise from `gain` (null: no low-pass, 1 everywhere).
void FillRelativeNoise(mocap::ZeroLagNoiseGain* gain, Experiment* e) {
  const Eigen::MatrixXd& measured = e->measured_rad;
  e->relative_noise = Eigen::MatrixXd::Ones(measured.rows(), measured.cols());
  if (gain == nullptr) return;
  for (Eigen::Index c = 0; c < measured.cols(); ++c) {
    const std::vector<double> relative =
        gain->Relative(measured.col(c).data(), static_cast<std::size_t>(measured.rows()));
    e->relative_noise.col(c) = Eigen::Map<const Eigen::VectorXd>(relative.data(), measured.rows());
  }
}

// Per joint: RMS about the median of the measured twist [deg], each frame's
// deviation over the low-pass's relative noise there (the twist was filtered
// like the angles), so that it is the interior's noise; NaN when a joint has
// fewer than 10 finite frames.
std::vector<double> TwistScatterDeg(const datasets::Array& twist, std::size_t first_frame,
                                    int joints, mocap::ZeroLagNoiseGain* gain,
                                    std::vector<double>* effective_samples) {
  std::vector<double> out(static_cast<std::size_t>(joints),
                          std::numeric_limits<double>::quiet_NaN());
  effective_samples->assign(static_cast<std::size_t>(joints), INFINITY);
  const std::size_t frames = twist.rows() - std::min(first_frame, twist.rows());
  for (int j = 0; j < joints; ++j) {
    const double* column = twist.values.data() + first_frame * twist.shape[1] + j;
    const std::vector<double> relative =
        gain ? gain->Relative(column, frames, twist.shape[1]) : std::vector<double>(frames, 1.0);
    std::vector<double> values, scale;
    for (std::size_t f = 0; f < frames; ++f) {
      const double v = column[f * twist.shape[1]];
      if (std::isfinite(v)) values.push_back(v), scale.push_back(relative[f]);
    }
    if (values.size() < 10) continue;
    const double median = Median(values);
    double sum = 0.0;
    std::vector<double> deviation;
    for (std::size_t k = 0; k < values.size(); ++k) {
      deviation.push_back((values[k] - median) / scale[k]);
      sum += deviation.back() * deviation.back();
    }
    out[static_cast<std::size_t>(j)] = std::sqrt(sum / static_cast<double>(values.size())) * kDeg;
    (*effective_samples)[static_cast<std::size_t>(j)] = EffectiveSampleSize({deviation});
  }
  return out;
}

}  // namespace

bool ExperimentLoadOptions::IsValid(std::string* error) const {
  if (noise_deg && !(*noise_deg > 0.0 && std::isfinite(*noise_deg))) {
    *error = "noise_deg must be > 0";
    return false;
  }
  if (!(min_noise_deg > 0.0 && std::isfinite(min_noise_deg))) {
    *error = "min_noise_deg must be > 0";
    return false;
  }
  return true;
}

namespace {

// The configuration given for every experiment (parsed once per job), as
// the arm of `recorded`: refused for a file whose own config_yaml describes
// another arm.
sim_io::ExperimentArm GivenArm(const datasets::ExperimentFile& recorded, const std::string& path,
                               const sim::Config& given) {
  if (!recorded.config_yaml.empty()) {
    const sim::Config own =
        sim::ParseConfig(recorded.config_yaml, path + ": attribute 'config_yaml'");
    const sim::ArmSize a = own.arm.size(), b = given.arm.size();
    if (a != b) {
      ThrowInputError(path, "attribute 'config_yaml'",
                      "describes an arm of " + std::to_string(a.joints) + " joints and " +
                          std::to_string(a.cables) + " driving cables, " + given.source_name +
                          " one of " + std::to_string(b.joints) + " and " +
                          std::to_string(b.cables));
    }
  }
  return {given, std::make_shared<const sim::ArmModel>(given.arm)};
}

// The recorded inputs the arm is simulated from (the check allows none: a
// recording without an actuator record), from the first sample on.
void SetInputs(const datasets::ExperimentFile& file, const std::string& path, Experiment* e) {
  const std::size_t n = file.input_time.rows();
  const std::size_t cables = file.input_length_change.shape[1];
  if (cables == 0) {
    ThrowInputError(path, "/input/length_change",
                    "has no cable columns: the experiment records no inputs, and "
                    "identification simulates each experiment from its own inputs");
  }
  if (n < 2) {
    ThrowInputError(path, "/input/time",
                    "has " + std::to_string(n) + " sample; the inputs need at least 2");
  }
  e->start_time_s = file.input_time.at(0);
  Eigen::VectorXd time(static_cast<Eigen::Index>(n));
  Eigen::MatrixXd length(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(cables));
  for (std::size_t i = 0; i < n; ++i) {
    time[static_cast<Eigen::Index>(i)] = file.input_time.at(i) - e->start_time_s;
    for (std::size_t c = 0; c < cables; ++c) {
      length(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) =
          file.input_length_change.at(i, c);
    }
  }
  e->inputs = std::make_shared<sim::CableInputs>(std::move(time), std::move(length));
}

// The measured frames the simulation can reach (from the first input sample
// on). Returns the index of the first.
std::size_t SetMeasuredFrames(const datasets::ExperimentFile& file, const std::string& path,
                              Experiment* e) {
  CCSRM_CHECK(file.measured_joint_angles.has_value());
  const datasets::Array& measured = *file.measured_joint_angles;  // F × J × 2 (checked)
  std::size_t first = 0;
  while (first < file.mocap_time.rows() && file.mocap_time.at(first) < e->start_time_s) ++first;
  const std::size_t frames = file.mocap_time.rows() - first;
  if (frames < 2) {
    ThrowInputError(path, "/mocap/time",
                    "has fewer than 2 frames at or after the first input sample (t = " +
                        std::to_string(e->start_time_s) + " s): nothing to simulate");
  }
  const std::size_t joints = static_cast<std::size_t>(e->joints);
  e->measured_rad.resize(static_cast<Eigen::Index>(frames), 2 * e->joints);
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = file.mocap_time.at(first + f);
    e->frame_time_s.push_back(t);
    e->sample_time_s.push_back(t - e->start_time_s);
    for (std::size_t j = 0; j < joints; ++j) {
      for (std::size_t a = 0; a < 2; ++a) {
        const double v = measured.values[((first + f) * joints + j) * 2 + a];
        e->measured_rad(static_cast<Eigen::Index>(f), static_cast<Eigen::Index>(2 * j + a)) = v;
        if (std::isfinite(v)) ++e->measured_samples;
      }
    }
  }
  if (e->measured_samples == 0) {
    ThrowInputError(path, "/measured/joint_angles",
                    "has no finite angle after t = " + std::to_string(e->start_time_s) + " s");
  }
  return first;
}

// The low-pass the pipeline applied, when the file records it.
void SetRecordedLowPass(const datasets::ExperimentFile& file, const std::string& path,
                        Experiment* e) {
  const auto quality = [&file](const char* name) {
    const auto it = file.mocap_quality.find(name);
    return it != file.mocap_quality.end() && it->second.size() == 1
               ? it->second.values[0]
               : std::numeric_limits<double>::quiet_NaN();
  };
  const double cutoff = quality("filter_cutoff_hz");
  const std::size_t frames = e->frame_time_s.size();
  if (!(std::isfinite(cutoff) && cutoff > 0.0 && frames >= 2)) return;
  Experiment::LowPass low_pass;
  low_pass.cutoff_hz = cutoff;
  low_pass.order = static_cast<int>(quality("filter_order"));
  low_pass.min_run_frames = static_cast<int>(quality("filter_min_run_frames"));
  low_pass.rate_hz =
      static_cast<double>(frames - 1) / (e->frame_time_s.back() - e->frame_time_s.front());
  if (low_pass.order < 1 || low_pass.order > 8 || low_pass.min_run_frames < 2 ||
      !(cutoff < 0.5 * low_pass.rate_hz)) {
    ThrowInputError(path, "/mocap/quality/filter_*",
                    "the recorded low-pass is not a valid filter (order 1..8, cutoff below "
                    "half the frame rate, minimum run >= 2)");
  }
  e->low_pass = low_pass;
}

// The noise of each joint: given, else from the twist scatter from frame
// `first` on, else the floor.
void SetNoise(const datasets::ExperimentFile& file, std::size_t first,
              const ExperimentLoadOptions& options, mocap::ZeroLagNoiseGain* gain, Experiment* e) {
  const std::size_t joints = static_cast<std::size_t>(e->joints);
  e->noise_deg.assign(joints, kMocapNoiseFloorDeg);
  e->noise_effective_samples.assign(joints, INFINITY);
  if (options.noise_deg) {
    e->noise_deg.assign(joints, *options.noise_deg);
    e->noise_source = "given";
  } else if (file.measured_joint_twist && file.measured_joint_twist->rank() == 2 &&
             file.measured_joint_twist->shape[1] == joints) {
    std::vector<double> effective;
    const std::vector<double> scatter =
        TwistScatterDeg(*file.measured_joint_twist, first, e->joints, gain, &effective);
    bool any = false;
    for (std::size_t j = 0; j < joints; ++j) {
      if (std::isfinite(scatter[j])) {
        e->noise_deg[j] = std::max(scatter[j], options.min_noise_deg);
        e->noise_effective_samples[j] = effective[j];
        any = true;
      }
    }
    e->noise_source = any ? "joint twist scatter" : "default floor 0.03 deg (too few twist frames)";
  } else {
    e->noise_source = "default floor 0.03 deg (no /measured/joint_twist)";
  }
}

}  // namespace

Experiment MakeExperiment(const datasets::ExperimentFile& recorded, const std::string& path,
                          const ExperimentLoadOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError(path, "noise", error);
  // The arm's configuration is parsed once: the given one once per job (it
  // replaces the file's own), else the file's own here, and the parsed arm
  // passed on to the checks and the mocap pipeline.
  std::optional<sim_io::ExperimentArm> given;
  datasets::ExperimentFile replaced;
  const datasets::ExperimentFile* input = &recorded;
  if (options.config) {
    given = GivenArm(recorded, path, *options.config);
    replaced = recorded;
    replaced.config_yaml = options.config->source_yaml;
    input = &replaced;
  }
  // The check of every door (config_yaml, cable columns, the measured
  // angles' shape and range) before any work. Without measured angles the
  // mocap pipeline runs, with default settings, and its output is checked
  // too: its angles follow the rigid bodies, which need not cover the arm.
  std::optional<sim_io::ExperimentArm> arm =
      sim_io::CheckExperimentAgainstConfig(*input, path, given ? &*given : nullptr);
  std::optional<mocap::ProcessedRecording> processed;
  if (!input->measured_joint_angles) {
    processed = mocap::AddMeasuredJointAngles(*input, path, {}, arm ? arm->model : nullptr);
    arm = sim_io::CheckExperimentAgainstConfig(processed->experiment, path, arm ? &*arm : nullptr);
  }
  const datasets::ExperimentFile& file = processed ? processed->experiment : *input;

  Experiment e;
  e.path = path;
  e.name = !file.name.empty() ? file.name : std::filesystem::path(path).stem().string();
  if (!arm) {
    ThrowInputError(path, "attribute 'config_yaml'",
                    "is empty: identification needs the arm's nominal configuration");
  }
  e.config = std::move(arm->config);
  e.model = std::move(arm->model);
  e.joints = e.model->num_joints();
  e.settled_poses = file.motion == datasets::RecordedMotion::kSettledPoses;
  if (e.settled_poses) {
    const std::string why = sim::WhyNotQuasiStatic(*e.model, e.config.parameters, e.config.solver);
    if (!why.empty())
      ThrowInputError(path, "attribute 'motion'", "settled_poses: the replay " + why);
  }
  SetInputs(file, path, &e);
  const std::size_t first = SetMeasuredFrames(file, path, &e);
  if (processed) {
    e.angles_from_pipeline = true;
    e.pipeline_report = processed->result.summary.BriefReport();
  }
  SetRecordedLowPass(file, path, &e);
  std::optional<mocap::ZeroLagNoiseGain> gain = LowPassNoiseGain(e);
  FillRelativeNoise(gain ? &*gain : nullptr, &e);
  SetNoise(file, first, options, gain ? &*gain : nullptr, &e);
  return e;
}

void Experiment::AsMeasured(Eigen::MatrixXd* angles_rad) const {
  CCSRM_CHECK(angles_rad->rows() == measured_rad.rows() &&
              angles_rad->cols() == measured_rad.cols());
  for (Eigen::Index c = 0; c < measured_rad.cols(); ++c) {
    for (Eigen::Index f = 0; f < measured_rad.rows(); ++f) {
      if (!std::isfinite(measured_rad(f, c))) (*angles_rad)(f, c) = kNaN;
    }
  }
  if (!low_pass) return;
  const std::vector<mocap::BiquadSection> sections =
      mocap::DesignButterworthLowPass(low_pass->order, low_pass->cutoff_hz, low_pass->rate_hz);
  for (Eigen::Index c = 0; c < angles_rad->cols(); ++c) {
    mocap::ZeroLagLowPass(sections, low_pass->cutoff_hz, low_pass->rate_hz,
                          angles_rad->col(c).data(), static_cast<std::size_t>(angles_rad->rows()),
                          1, static_cast<std::size_t>(low_pass->min_run_frames));
  }
}

void SetRelativeNoise(Experiment* e) {
  std::optional<mocap::ZeroLagNoiseGain> gain = LowPassNoiseGain(*e);
  FillRelativeNoise(gain ? &*gain : nullptr, e);
}

Experiment LoadExperiment(const std::string& path, const ExperimentLoadOptions& options) {
  return MakeExperiment(datasets::ReadExperimentFile(path), path, options);
}

}  // namespace ccsrm::identify
