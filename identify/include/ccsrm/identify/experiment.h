#pragma once
// A recorded experiment as identification uses it (SPEC 4, 6): simulated
// from its own inputs, on its own time base, and compared with its measured
// joint angles at its own mocap frames.
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {

// The noise floor of measured joint angles, RMS per angle [deg]: what
// identification weights its residuals by (issue 10).
inline constexpr double kMocapNoiseFloorDeg = 0.03;

struct ExperimentLoadOptions {
  // Measurement noise of every joint angle, standard deviation after
  // processing [deg]: the weight of the residuals. Unset (the default): it is
  // estimated per joint from the scatter of the joint's measured twist. A
  // universal joint cannot twist, so the twist the mocap pipeline reports
  // (/measured/joint_twist) is measurement noise, fitted and filtered like
  // θx and θy; its RMS about the median is that noise. Without a twist
  // record the 0.03 deg floor of 0.2 mm marker noise is used, and the
  // experiment's noise_source says so.
  std::optional<double> noise_deg;
  // No joint's noise is taken below this [deg]: a twist that a filter has
  // flattened must not give one joint a weight thousands of times the
  // others'. Default: a tenth of the 0.03 deg floor.
  double min_noise_deg = 0.003;
  // Measurement noise of a tracked point's coordinates, standard deviation
  // per axis [mm]: the weight of tracked-point residuals. Default: 0.5 mm, a
  // capture system's marker noise with the marker's own placement on its
  // body (the recorded robot's rest tip scatters by 0.3 mm in z).
  double point_noise_mm = 0.5;
  // The arm's nominal configuration to use instead of the file's own
  // config_yaml (`ccsrm loop --config FILE`, `ccsrm predict --config FILE`,
  // as `ccsrm mocap process --config` stores one), parsed once by the caller
  // for every experiment (sim::LoadConfig; its source_name names it in
  // messages). Null (the default): the file's config_yaml. The experiment is
  // then checked against this arm, and a file whose own config_yaml
  // describes an arm of other joints or driving cables is refused.
  std::shared_ptr<const sim::Config> config;

  bool IsValid(std::string* error) const;
};

// A point tracked on one body (a tip marker): compared in its position
// when the recording holds no link poses (issue 46).
struct TrackedPoint {
  std::string name;                                        // the marker's
  int link = 0;                                            // 0 the base, else 1-based link index
  Eigen::Vector3d position_B_m = Eigen::Vector3d::Zero();  // in that body's frame
};

// The rigid motion that carries points simulated in W onto the measured
// ones: measured ≈ R_CW simulated + p_CW.
struct RigidPlacement {
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_CW_m = Eigen::Vector3d::Zero();
};

// How a run's tracked points are put in the frame they were recorded in.
enum class PointPlacement {
  kWorld,  // recorded in W: compared as simulated
  // Recorded in the capture system's own frame, placed relative to W by a
  // rigid motion nobody measured: each run is placed by the rotation and
  // offset that best fit its points to the measured ones (least squares,
  // Umeyama's closed form). The placement is so eliminated from the fit
  // (variable projection: the finite-difference Jacobian of the placed
  // residual is the reduced problem's), and its 6 values are estimated with
  // every run.
  kFittedRigidMotion,
  // Recorded in the capture frame, placed by a known rigid motion
  // (Experiment::given_placement: a fit's, for a prediction).
  kGiven,
};

// What a simulation of the experiment needs, and what it is compared with.
struct Experiment {
  std::string name;  // the file's `name` attribute, else its stem
  std::string path;  // where it was read from (messages)
  // The nominal configuration (the file's config_yaml): the arm, the values
  // of every parameter identification does not change, and the solver.
  sim::Config config;
  std::shared_ptr<const sim::ArmModel> model;
  // /input/length_change on the simulation's time base: simulation time 0 is
  // the first input sample, where the arm is taken to be straight and at rest.
  std::shared_ptr<const sim::CableInputs> inputs;
  double start_time_s = 0.0;  // experiment time of simulation time 0
  // The mocap frames at or after start_time_s: their experiment times, and
  // the same on the simulation's time base.
  std::vector<double> frame_time_s;
  std::vector<double> sample_time_s;
  // Per frame, the label of the input pattern it belongs to (the last
  // /input/labels entry at or before the frame); empty without labels.
  std::vector<std::string> frame_labels;
  int joints = 0;
  // What was measured, row per frame: column 2 j + a the angle of joint j
  // (0-based) about axis a (0 θx, 1 θy) [rad], then column 2 J + 3 p + c
  // coordinate c of tracked point p [m]; NaN where not measured. An
  // experiment of tracked points has every angle column NaN.
  Eigen::MatrixXd measured;
  std::vector<TrackedPoint> tracked_points;
  PointPlacement point_placement = PointPlacement::kWorld;
  RigidPlacement given_placement;  // used with PointPlacement::kGiven
  double point_noise_mm = 0.5;     // ExperimentLoadOptions::point_noise_mm
  std::vector<double> noise_deg;   // per joint, far from a recording's ends and gaps
  // The noise of each measured angle over its joint's noise_deg, laid out as
  // measured: 1 without a recorded low-pass; with one, the filter's own
  // white-noise gain at the frame over its interior gain
  // (mocap::ZeroLagNoiseGain), up to about 2 at a run's ends, where the
  // zero-lag low-pass sits on a pivot of fewer samples. NaN where nothing
  // was measured. Empty (an experiment built in code): 1 everywhere.
  Eigen::MatrixXd relative_noise;
  std::string noise_source;  // "given", "joint twist scatter" or "default floor ..."
  // Per joint, the independent samples its noise was estimated from (the
  // twist's frames over their integrated autocorrelation time): how well
  // the noise itself is known. Infinite for a given noise or the floor, and
  // when empty (an experiment built in code).
  std::vector<double> noise_effective_samples;
  // The file's `motion` is settled_poses: every run replays it
  // quasi-statically (sim::SimulationOptions::quasi_static).
  bool settled_poses = false;
  // True when the file had no /measured/joint_angles and the mocap pipeline
  // computed them at load, with default settings.
  bool angles_from_pipeline = false;
  std::string pipeline_report;       // the pipeline's one-line quality summary, when it ran
  std::size_t measured_samples = 0;  // finite entries of measured

  // The zero-lag low-pass the mocap pipeline applied to the measured angles,
  // from the file's quality figures (filter_cutoff_hz, ...); unset when the
  // file does not record one or the cutoff is 0.
  struct LowPass {
    double cutoff_hz = 0.0;
    int order = 0;
    int min_run_frames = 0;
    double rate_hz = 0.0;  // of the frames
  };
  std::optional<LowPass> low_pass;

  // Makes simulated angles [rad], laid out as measured, comparable with
  // the measured ones: NaN where nothing was measured, then the pipeline's
  // low-pass on every run of frames between gaps, as the pipeline did to the
  // true angles. Without the filter, a 1 Hz low-pass would shave the fast
  // parts of the measured motion that the raw simulation keeps, and a fit
  // would trade damping for that difference.
  void AsMeasured(Eigen::MatrixXd* angles_rad) const;

  // The noise [deg] of measured(frame, column) for an angle column: what a
  // residual there is weighed by, so that a recording's ends count for what
  // they know.
  double NoiseDeg(Eigen::Index frame, Eigen::Index column) const {
    const double joint = noise_deg[static_cast<std::size_t>(column / 2)];
    return relative_noise.size() == 0 ? joint : joint * relative_noise(frame, column);
  }

  bool IsPointColumn(Eigen::Index column) const { return column >= 2 * joints; }
  // (simulated - measured) at (frame, column) over its noise: the weighted
  // residual of an angle in degrees over degrees, of a tracked point's
  // coordinate in mm over mm.
  double WeightedResidual(Eigen::Index frame, Eigen::Index column, double simulated) const {
    const double d = simulated - measured(frame, column);
    if (IsPointColumn(column)) return d * 1e3 / point_noise_mm;
    return d * (180.0 / 3.14159265358979323846) / NoiseDeg(frame, column);
  }

  // Simulated time [s] of a run sampled on the solver's output grid rather
  // than at sample times (FrameExperiment: `ccsrm derivatives` under MPI,
  // sample_time_s empty); 0 for a recording, whose runs end at its last frame.
  double simulated_s = 0.0;

  double duration_s() const {
    if (simulated_s > 0.0) return simulated_s;
    return sample_time_s.empty() ? 0.0 : sample_time_s.back();
  }
};

// Builds the experiment from a file already read. A file without
// /measured/joint_angles first goes through the mocap pipeline with default
// settings (mocap::AddMeasuredJointAngles); angles_from_pipeline says so.
// Throws InputError
// "<path>: <field>: <problem>" for an experiment that cannot be identified:
// what sim_io::CheckExperimentAgainstConfig refuses (a config_yaml that does
// not parse, inputs for another number of cables than the arm has, measured
// angles of another number of joints, none finite, or outside a universal
// joint's range), no inputs, no config_yaml, no mocap frame at or after the
// first input sample, or no finite measured angle after it.
Experiment MakeExperiment(const datasets::ExperimentFile& file, const std::string& path,
                          const ExperimentLoadOptions& options);

// Fills the tracked-point columns of `simulated` (laid out as e.measured)
// with the points of each trajectory frame, placed as e.point_placement says
// (the best rigid motion when the points were recorded in the capture frame,
// over every frame and point measured; the given one under kGiven). Returns
// the placement used (the identity in W, and when fewer than three points are
// measured to fit one).
RigidPlacement RecordTrackedPoints(const Experiment& e, const sim::Trajectory& trajectory,
                                   Eigen::MatrixXd* simulated);

// The errors of simulated tracked points against the measured ones, per point
// over the frames where it was measured [mm]: the RMS of the Euclidean
// distance, and the same after removing the mean offset (the publishing
// project's metric on the recorded robot, issue 46).
struct TrackedPointErrors {
  std::vector<double> rms_mm;
  std::vector<double> rms_mean_removed_mm;
  std::vector<Eigen::Vector3d> mean_offset_mm;  // mean of simulated - measured
  std::vector<std::size_t> frames;
};
TrackedPointErrors PointErrors(const Experiment& e, const Eigen::MatrixXd& simulated);

// Fills e->relative_noise from e->low_pass and the gaps of e->measured.
// MakeExperiment does; an experiment built in code with a low-pass calls it
// after setting both.
void SetRelativeNoise(Experiment* e);

// Reads `path` (ccsrm-dataset/1) and builds the experiment from it.
Experiment LoadExperiment(const std::string& path, const ExperimentLoadOptions& options);

}  // namespace ccsrm::identify
