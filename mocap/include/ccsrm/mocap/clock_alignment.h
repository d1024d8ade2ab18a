#pragma once
// Putting an actuator log on the mocap clock. The two clocks start at
// different moments and tick at slightly different rates; the model is
//   t_log = offset_s + (1 + drift) × t_mocap,
// drift a fraction (80 ppm = 8e-5). Four ways to find it: edges of a trigger
// pulse seen by both (AlignByTrigger), the offset that best maps the
// measured joint angles onto those of one simulation driven by the log
// (AlignBySimulation), the offset at which the logged lengths best explain
// the measured angles through the kinematics of a quasi-static arm
// (AlignByKinematics), or a value given by the user.
#include <Eigen/Core>

#include <limits>
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::mocap {

struct ClockFit {
  std::string method;  // "trigger", "estimate" (either estimate; the note says which), "offset"
  double offset_s = 0.0;
  double offset_sigma_s = 0.0;  // one standard deviation
  double drift = 0.0;           // fraction (1e-6 = 1 ppm)
  double drift_sigma = 0.0;     // 0 when the drift was not estimated
  std::string note;             // one line: what was matched and how well

  // Log time of a mocap time, and back.
  double LogTime(double mocap_time_s) const { return offset_s + (1.0 + drift) * mocap_time_s; }
  double MocapTime(double log_time_s) const { return (log_time_s - offset_s) / (1.0 + drift); }
};

// ---- Edges --------------------------------------------------------------------

struct EdgeOptions {
  // Level the signal crosses. NaN (the default): half-way between the
  // signal's smallest and largest finite values.
  double threshold = std::numeric_limits<double>::quiet_NaN();
  bool rising = true;  // false: falling edges
  // A crossing only counts once the signal has been on the other side of the
  // threshold for at least this long [s] (debounces noise around the level).
  double min_separation_s = 0.005;
  // How a crossing's time is taken. true: by linear interpolation between
  // the two samples (an analog channel sampling a voltage that rises over a
  // sample or more). false: the first sample past the threshold (a
  // controller's log, where the output was set at that tick).
  bool interpolate = true;
};

// Times of the edges of `values` sampled at `time_s` (same length, time
// increasing). NaN samples break the signal (no edge across them).
std::vector<double> FindEdges(const Eigen::VectorXd& time_s, const Eigen::VectorXd& values,
                              const EdgeOptions& options = {});

// ---- Alignment by trigger ---------------------------------------------------

struct TriggerAlignmentOptions {
  // Timing uncertainty of one edge on each clock (one standard deviation,
  // s): a quantisation of one sample period / √12 when unknown. Set by the
  // caller from the sample periods.
  double mocap_edge_sigma_s = 0.0;
  double log_edge_sigma_s = 0.0;
  // Largest plausible rate difference of two clocks (crystal oscillators
  // are within ±100 ppm; 1000 ppm leaves room for cheap ones). Pairings
  // implying more are rejected.
  double max_drift = 1e-3;
  // Estimate the drift when at least two edges pair up (else offset only).
  bool estimate_drift = true;
};

// Pairs the mocap edges with the log edges in order, trying every shift of
// one sequence against the other such that the shorter one is paired whole
// (a log usually starts before the mocap and holds edges it did not see),
// and fits offset and drift by least squares. Throws InputError (labelled
// `source`) when there are no edges on one side, when no pairing is
// plausible (a residual well above the edge timing, or a drift above
// max_drift), or when two pairings fit equally well ("ambiguous alignment").
ClockFit AlignByTrigger(const std::vector<double>& mocap_edges_s,
                        const std::vector<double>& log_edges_s,
                        const TriggerAlignmentOptions& options, const std::string& source);

// ---- Alignment by estimation (simulation or kinematics) ----------------------

// The search of AlignBySimulation and AlignByKinematics.
struct KinematicAlignmentOptions {
  // Offsets searched [s]: every log time that puts the whole mocap recording
  // inside the log. Coarse to fine: a grid of `coarse_step_s` with the
  // misfit on every k-th frame (k frames ≈ one coarse step), then its five
  // lowest local minima on a grid of `grid_step_s` (0: one mocap frame)
  // within one coarse step, with every frame, refined between grid points.
  // 0.05 s is well below the time over which the misfit of a motion slow
  // enough to measure (below the arm's first mode, ~1 Hz) changes.
  double coarse_step_s = 0.05;
  double grid_step_s = 0.0;
  // Search only offsets within search_half_width_s of search_center_s
  // (NaN, the default: every offset the log allows). A check of a known
  // alignment needs a window, not a log's whole length.
  double search_center_s = std::numeric_limits<double>::quiet_NaN();
  double search_half_width_s = std::numeric_limits<double>::quiet_NaN();
  // Two minima of the misfit further apart than `ambiguity_separation_s`
  // whose misfits differ by less than `ambiguity_chi2` (in units of the
  // residual variance times N / N_eff, the effective sample correction of
  // correlated residuals; 9 = three standard deviations) make the alignment
  // ambiguous.
  double ambiguity_separation_s = 0.05;
  double ambiguity_chi2 = 9.0;
  // Also estimate the drift (worth it for long recordings: 100 ppm over
  // 100 s is 10 ms, a frame), over ±max_drift on a grid of drift_step,
  // refined between grid points. Off: drift 0.
  bool estimate_drift = false;
  double max_drift = 1e-3;   // crystal clocks are within ±100 ppm; room for cheap ones
  double drift_step = 1e-5;  // 10 ppm
};

// Finds the offset (and, with options.estimate_drift, the drift; else drift
// 0) at which the logged length changes best
// explain the cable path lengths of the measured joint angles: for every
// frame with all angles finite, q_k = L_k(0) − L_k(θ(t)) by kinematics
// (what a quasi-static arm pulls in), compared per cable through an affine
// fit q_k ≈ a_k + b_k · l_k(t_log) (cable stretch and the log's own zero
// absorbed). `angles` is F × J × 2 row-major as in /measured/joint_angles.
// Assumes a quasi-static arm: an arm that lags its inputs (friction: about
// 50 ms on the generated case-2 arm) biases it by its lag. The offset's
// uncertainty is the misfit's curvature with the residual variance scaled by
// N / N_eff (identification's correction for correlated residuals). Method
// "estimate". Throws InputError (labelled `source`) when the log
// cannot cover the recording, the motion is too small to align on, or the
// misfit has two equally good minima.
ClockFit AlignByKinematics(const sim::ArmModel& model, const std::vector<double>& mocap_time_s,
                           const std::vector<double>& angles, const Eigen::VectorXd& log_time_s,
                           const Eigen::MatrixXd& log_length_change_m,
                           const KinematicAlignmentOptions& options, const std::string& source);

// The offset (and with options.estimate_drift the drift) that best maps the
// measured joint angles onto the simulated ones: the arm (model, prior
// `parameters`, `solver`) is simulated once from rest, driven by the log on
// its own clock from its first sample (the log's zero: the arm straight and
// at rest), sampled every half mocap frame; being time-invariant, the arm
// answers inputs shifted by δ with this response shifted by δ, so the misfit
// of every offset is the measured angles (minus a per-channel constant, a
// marker calibration's bias) against the simulated ones interpolated at
// t_log. Uncertainty and ambiguity as AlignByKinematics. Method "estimate".
// Throws InputError as AlignByKinematics, and when the simulation does not
// complete.
ClockFit AlignBySimulation(const sim::ArmModel& model, const sim::ArmParameters& parameters,
                           const sim::SolverConfig& solver, const std::vector<double>& mocap_time_s,
                           const std::vector<double>& angles, const Eigen::VectorXd& log_time_s,
                           const Eigen::MatrixXd& log_length_change_m,
                           const KinematicAlignmentOptions& options, const std::string& source);

// The log's lengths at the mocap times, by linear interpolation (a log
// sampled faster than the mocap keeps its values between samples). Throws
// InputError when a mocap time falls outside the log.
Eigen::MatrixXd ResampleOntoMocapTimes(const ClockFit& fit, const std::vector<double>& mocap_time_s,
                                       const Eigen::VectorXd& log_time_s,
                                       const Eigen::MatrixXd& log_length_change_m,
                                       const std::string& source);

}  // namespace ccsrm::mocap
