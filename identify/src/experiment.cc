#include "ccsrm/identify/experiment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include <Eigen/Geometry>

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
  const Eigen::MatrixXd& measured = e->measured;
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
  if (!(point_noise_mm > 0.0 && std::isfinite(point_noise_mm))) {
    *error = "point_noise_mm must be > 0";
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

// The mocap frames the simulation can reach (from the first input sample
// on), into e's frame and sample times. Returns the index of the first.
std::size_t SetFrames(const datasets::ExperimentFile& file, const std::string& path,
                      Experiment* e) {
  std::size_t first = 0;
  while (first < file.mocap_time.rows() && file.mocap_time.at(first) < e->start_time_s) ++first;
  const std::size_t frames = file.mocap_time.rows() - first;
  if (frames < 2) {
    ThrowInputError(path, "/mocap/time",
                    "has fewer than 2 frames at or after the first input sample (t = " +
                        std::to_string(e->start_time_s) + " s): nothing to simulate");
  }
  std::size_t input = 0;
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = file.mocap_time.at(first + f);
    e->frame_time_s.push_back(t);
    e->sample_time_s.push_back(t - e->start_time_s);
    if (file.input_labels.empty()) continue;
    while (input + 1 < file.input_labels.size() && file.input_time.at(input + 1) <= t) ++input;
    e->frame_labels.push_back(file.input_labels[input]);
  }
  return first;
}

// The measured joint angles from frame `first` on.
void SetMeasuredAngles(const datasets::ExperimentFile& file, const std::string& path,
                       std::size_t first, Experiment* e) {
  CCSRM_CHECK(file.measured_joint_angles.has_value());
  const datasets::Array& measured = *file.measured_joint_angles;  // F × J × 2 (checked)
  const std::size_t joints = static_cast<std::size_t>(e->joints);
  const std::size_t frames = e->frame_time_s.size();
  e->measured.resize(static_cast<Eigen::Index>(frames), 2 * e->joints);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t j = 0; j < joints; ++j) {
      for (std::size_t a = 0; a < 2; ++a) {
        const double v = measured.values[((first + f) * joints + j) * 2 + a];
        e->measured(static_cast<Eigen::Index>(f), static_cast<Eigen::Index>(2 * j + a)) = v;
        if (std::isfinite(v)) ++e->measured_samples;
      }
    }
  }
  if (e->measured_samples == 0) {
    ThrowInputError(path, "/measured/joint_angles",
                    "has no finite angle after t = " + std::to_string(e->start_time_s) + " s");
  }
}

// A file whose markers cannot give link poses (a body with fewer than the
// three markers a pose needs, as a pose log's one tip marker) and that
// holds no measured angles is compared in its markers' positions.
bool TracksPoints(const datasets::ExperimentFile& file) {
  if (file.measured_joint_angles || file.rigid_bodies.empty()) return false;
  return std::any_of(file.rigid_bodies.begin(), file.rigid_bodies.end(),
                     [](const datasets::RigidBody& b) { return b.marker_names.size() < 3; });
}

// Every marker of every rigid body as a tracked point, its positions from
// frame `first` on.
void SetTrackedPoints(const datasets::ExperimentFile& file, const std::string& path,
                      std::size_t first, Experiment* e) {
  const int links = e->model->num_links();
  std::vector<std::size_t> marker_column;
  for (const datasets::RigidBody& body : file.rigid_bodies) {
    const std::string field = "/mocap/rigid_bodies/" + body.name;
    int link = -1;
    if (body.name == "base") {
      link = 0;
    } else if (body.name.rfind("link", 0) == 0 && body.name.size() > 4 &&
               body.name.find_first_not_of("0123456789", 4) == std::string::npos) {
      link = std::stoi(body.name.substr(4));
    }
    if (link < 0 || link > links) {
      ThrowInputError(
          path, field,
          "names no body of the arm ('base' or 'link1' to 'link" + std::to_string(links) + "')");
    }
    for (std::size_t m = 0; m < body.marker_names.size(); ++m) {
      const auto it =
          std::find(file.marker_names.begin(), file.marker_names.end(), body.marker_names[m]);
      CCSRM_CHECK(it != file.marker_names.end());  // the file's own check
      marker_column.push_back(static_cast<std::size_t>(it - file.marker_names.begin()));
      e->tracked_points.push_back(
          {body.marker_names[m], link,
           Eigen::Vector3d(body.local_position.at(m, 0), body.local_position.at(m, 1),
                           body.local_position.at(m, 2))});
    }
  }
  const std::size_t frames = e->frame_time_s.size();
  const std::size_t markers = file.marker_names.size();
  const Eigen::Index angles = 2 * e->joints;
  e->measured = Eigen::MatrixXd::Constant(
      static_cast<Eigen::Index>(frames),
      angles + 3 * static_cast<Eigen::Index>(e->tracked_points.size()), kNaN);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t p = 0; p < marker_column.size(); ++p) {
      const double* xyz =
          &file.mocap_markers.values[((first + f) * markers + marker_column[p]) * 3];
      if (!(std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2]))) continue;
      for (Eigen::Index c = 0; c < 3; ++c) {
        e->measured(static_cast<Eigen::Index>(f), angles + 3 * static_cast<Eigen::Index>(p) + c) =
            xyz[c];
      }
      e->measured_samples += 3;
    }
  }
  if (e->measured_samples == 0) {
    ThrowInputError(
        path, "/mocap/markers",
        "has no finite tracked point after t = " + std::to_string(e->start_time_s) + " s");
  }
  e->point_placement = file.marker_frame == datasets::MarkerFrame::kCapture
                           ? PointPlacement::kFittedRigidMotion
                           : PointPlacement::kWorld;
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
  const bool tracks_points = TracksPoints(*input);
  if (!input->measured_joint_angles && !tracks_points) {
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
  const std::size_t first = SetFrames(file, path, &e);
  if (tracks_points) {
    SetTrackedPoints(file, path, first, &e);
  } else {
    SetMeasuredAngles(file, path, first, &e);
  }
  if (processed) {
    e.angles_from_pipeline = true;
    e.pipeline_report = processed->result.summary.BriefReport();
  }
  SetRecordedLowPass(file, path, &e);
  std::optional<mocap::ZeroLagNoiseGain> gain = LowPassNoiseGain(e);
  FillRelativeNoise(gain ? &*gain : nullptr, &e);
  SetNoise(file, first, options, gain ? &*gain : nullptr, &e);
  e.point_noise_mm = options.point_noise_mm;
  if (tracks_points) {
    char noise[96];
    std::snprintf(noise, sizeof noise, "tracked points, %.3g mm per coordinate", e.point_noise_mm);
    e.noise_source = noise;
  }
  return e;
}

void Experiment::AsMeasured(Eigen::MatrixXd* angles_rad) const {
  CCSRM_CHECK(angles_rad->rows() == measured.rows() && angles_rad->cols() == measured.cols());
  for (Eigen::Index c = 0; c < measured.cols(); ++c) {
    for (Eigen::Index f = 0; f < measured.rows(); ++f) {
      if (!std::isfinite(measured(f, c))) (*angles_rad)(f, c) = kNaN;
    }
  }
  if (!low_pass) return;
  const std::vector<mocap::BiquadSection> sections =
      mocap::DesignButterworthLowPass(low_pass->order, low_pass->cutoff_hz, low_pass->rate_hz);
  for (Eigen::Index c = 0; c < 2 * joints; ++c) {
    mocap::ZeroLagLowPass(sections, low_pass->cutoff_hz, low_pass->rate_hz,
                          angles_rad->col(c).data(), static_cast<std::size_t>(angles_rad->rows()),
                          1, static_cast<std::size_t>(low_pass->min_run_frames));
  }
}

namespace {

// The rigid motion that best carries the first `frames` rows of the
// simulated tracked points onto the measured ones (Umeyama's closed form over
// every point both have); false with fewer than three.
bool FitPlacement(const Experiment& e, const Eigen::MatrixXd& simulated, std::size_t frames,
                  RigidPlacement* placement) {
  const Eigen::Index angles = 2 * e.joints;
  const Eigen::Index points = static_cast<Eigen::Index>(e.tracked_points.size());
  std::vector<Eigen::Vector3d> from, to;
  for (std::size_t f = 0; f < frames; ++f) {
    const Eigen::Index row = static_cast<Eigen::Index>(f);
    for (Eigen::Index p = 0; p < points; ++p) {
      const Eigen::Vector3d s = simulated.block<1, 3>(row, angles + 3 * p).transpose();
      const Eigen::Vector3d m = e.measured.block<1, 3>(row, angles + 3 * p).transpose();
      if (s.allFinite() && m.allFinite()) from.push_back(s), to.push_back(m);
    }
  }
  if (from.size() < 3) return false;
  Eigen::Matrix3Xd src(3, static_cast<Eigen::Index>(from.size())), dst(3, src.cols());
  for (std::size_t k = 0; k < from.size(); ++k) {
    src.col(static_cast<Eigen::Index>(k)) = from[k];
    dst.col(static_cast<Eigen::Index>(k)) = to[k];
  }
  const Eigen::Matrix4d X_CW = Eigen::umeyama(src, dst, /*with_scaling=*/false);
  placement->R_CW = X_CW.topLeftCorner<3, 3>();
  placement->p_CW_m = X_CW.topRightCorner<3, 1>();
  return true;
}

}  // namespace

RigidPlacement RecordTrackedPoints(const Experiment& e, const sim::Trajectory& trajectory,
                                   Eigen::MatrixXd* simulated) {
  const Eigen::Index angles = 2 * e.joints;
  const Eigen::Index points = static_cast<Eigen::Index>(e.tracked_points.size());
  CCSRM_CHECK(simulated->cols() == angles + 3 * points);
  const std::size_t frames =
      std::min(trajectory.size(), static_cast<std::size_t>(simulated->rows()));
  for (std::size_t f = 0; f < frames; ++f) {
    const sim::TrajectoryFrame& frame = trajectory.frames[f];
    for (Eigen::Index p = 0; p < points; ++p) {
      const TrackedPoint& point = e.tracked_points[static_cast<std::size_t>(p)];
      Eigen::Vector3d p_WP = point.position_B_m;  // the base's frame is W
      if (point.link > 0) {
        const Eigen::Matrix<double, 7, 1>& pose =
            frame.link_pose[static_cast<std::size_t>(point.link - 1)];
        const Eigen::Quaterniond q_WB(pose[3], pose[4], pose[5], pose[6]);
        p_WP = pose.head<3>() + q_WB.normalized() * point.position_B_m;
      }
      simulated->block<1, 3>(static_cast<Eigen::Index>(f), angles + 3 * p) = p_WP.transpose();
    }
  }
  RigidPlacement placement;
  if (e.point_placement == PointPlacement::kWorld) return placement;
  if (e.point_placement == PointPlacement::kGiven) {
    placement = e.given_placement;
  } else if (!FitPlacement(e, *simulated, frames, &placement)) {
    return placement;
  }
  for (std::size_t f = 0; f < frames; ++f) {
    for (Eigen::Index p = 0; p < points; ++p) {
      auto xyz = simulated->block<1, 3>(static_cast<Eigen::Index>(f), angles + 3 * p);
      xyz = (placement.R_CW * xyz.transpose() + placement.p_CW_m).transpose();
    }
  }
  return placement;
}

TrackedPointErrors PointErrors(const Experiment& e, const Eigen::MatrixXd& simulated) {
  CCSRM_CHECK(simulated.rows() == e.measured.rows() && simulated.cols() == e.measured.cols());
  TrackedPointErrors out;
  const Eigen::Index angles = 2 * e.joints;
  for (std::size_t p = 0; p < e.tracked_points.size(); ++p) {
    const Eigen::Index c = angles + 3 * static_cast<Eigen::Index>(p);
    std::vector<Eigen::Vector3d> d;
    for (Eigen::Index f = 0; f < e.measured.rows(); ++f) {
      const Eigen::Vector3d diff =
          (simulated.block<1, 3>(f, c) - e.measured.block<1, 3>(f, c)).transpose() * 1e3;
      if (diff.allFinite()) d.push_back(diff);
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& v : d) mean += v;
    if (!d.empty()) mean /= static_cast<double>(d.size());
    double sum = 0.0, sum_removed = 0.0;
    for (const Eigen::Vector3d& v : d) {
      sum += v.squaredNorm();
      sum_removed += (v - mean).squaredNorm();
    }
    const double n = static_cast<double>(d.size());
    out.rms_mm.push_back(d.empty() ? kNaN : std::sqrt(sum / n));
    out.rms_mean_removed_mm.push_back(d.empty() ? kNaN : std::sqrt(sum_removed / n));
    out.mean_offset_mm.push_back(mean);
    out.frames.push_back(d.size());
  }
  return out;
}

void SetRelativeNoise(Experiment* e) {
  std::optional<mocap::ZeroLagNoiseGain> gain = LowPassNoiseGain(*e);
  FillRelativeNoise(gain ? &*gain : nullptr, e);
}

Experiment LoadExperiment(const std::string& path, const ExperimentLoadOptions& options) {
  return MakeExperiment(datasets::ReadExperimentFile(path), path, options);
}

}  // namespace ccsrm::identify
