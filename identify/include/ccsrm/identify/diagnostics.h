#pragma once
// Residual diagnostics (SPEC 7): what the residual a fitted model leaves
// looks like, per joint and axis, and which signals it follows. The loop
// (loop.h) reports them as the evidence beside each candidate effect; its
// decisions rest on scores and refits, not on these.
//
// The residual is simulated - measured [deg] (SPEC 5's sign, as in every
// fit, page and CSV), at every measured frame, each frame over its relative
// noise (Experiment::NoiseDeg): at a recording's ends the zero-lag low-pass
// leaves up to twice the interior's noise, which is not physics. Its signals
// are taken from the simulated motion:
//   rate_sign   sign of the joint rate (0 while the joint is still)
//   rate        joint rate
//   angle       joint angle (a tracked point's coordinate)
//   heading     the heading of the joint's distal link: the sum of the
//               angles of this axis from joint 1 to the joint (none for a
//               tracked point)
//   time        time since the start of the experiment
//   input_rate  rate of the input cable that moves most
//   constant    the residual's mean (value: mean / RMS)
//   hold_drift  time within each hold (input still), from its middle
//   hysteresis  the loop area of residual against angle, ∮ r dθ, over
//               RMS(r) Σ|dθ| (±1 for a residual that is +RMS on the way out
//               and -RMS on the way back)
//   lag         the share of the residual that a time shift of the
//               simulated motion explains
// Correlations carry a 95 % band 1.96 / sqrt(n_eff), with n_eff the
// number of independent pairs (Bartlett: n over 1 + 2 Σ ρ_r(k) ρ_s(k)):
// mocap residuals are strongly autocorrelated, and counting frames would
// call every correlation significant.
#include <Eigen/Core>
#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"

namespace ccsrm::identify {

// The signal names, in report order.
const std::vector<std::string>& ResidualSignalNames();

// A stretch of an experiment: the inputs moving ("motion k") or still
// ("hold k").
struct ProtocolPhase {
  std::string name;
  double start_s = 0.0, end_s = 0.0;  // experiment time
};

struct SignalEvidence {
  std::string signal;
  double value = 0.0;  // correlation (or the normalised statistic above), in [-1, 1]
  double band = 0.0;   // 95 % band of value under "no relation"
  bool significant() const { return std::abs(value) > band; }
};

// A channel: a joint's axis, or a tracked point's coordinate in the capture
// frame (an experiment of tracked points, issue 46). A tracked point's
// channel is in mm where a joint's is in deg (every field named _deg below,
// as in ChannelAboveNoise), and has no heading.
struct ChannelDiagnostics {
  std::size_t experiment = 0;
  int joint = 0;      // 1-based; 0 for a tracked point's coordinate
  int axis = 0;       // 0 θx, 1 θy; of a tracked point 0 x, 1 y, 2 z
  std::string point;  // the tracked point's name (Experiment::tracked_points)
  std::size_t samples = 0;
  double rms_deg = 0.0;
  double mean_deg = 0.0;
  double noise_deg = 0.0;  // the experiment's noise of the joint
  // Autocorrelation at lags 1..autocorrelation.size() frames, its 95 % band
  // for white noise (1.96 / sqrt(samples)), the share of lags outside the
  // band (about 5 % for white noise) and the integrated autocorrelation time.
  std::vector<double> autocorrelation;
  double whiteness_band = 0.0;
  double lags_outside_band = 0.0;
  double autocorrelation_time = 1.0;
  double effective_samples = 0.0;
  std::vector<SignalEvidence> evidence;  // in ResidualSignalNames() order
  double hold_drift_degps = 0.0;         // mean slope of the residual during holds
  double hysteresis_deg2 = 0.0;          // ∮ r dθ [deg²]
  std::vector<double> phase_rms_deg;     // per phase of the experiment
};

// "joint 3 θx", or of a tracked point's coordinate "point tip x".
std::string ChannelName(int joint, int axis, const std::string& point);

struct ExperimentDiagnostics {
  std::string name;
  std::vector<ProtocolPhase> phases;
  // The shift of the simulated motion that best matches the measured one
  // (positive: the arm moves later than simulated), within ±0.5 s, and the
  // share of the residual's mean square it removes.
  double lag_s = 0.0;
  double lag_explained = 0.0;
  double rms_deg = 0.0;
};

struct ResidualDiagnostics {
  std::vector<ExperimentDiagnostics> experiments;
  std::vector<ChannelDiagnostics> channels;  // experiment, joint, axis order
  // Pooled over every channel: each signal's correlation with the residual
  // (channels weighted by their residual energy), its band (from the summed
  // effective pairs), and the cross-correlation at lags_s (signal shifted
  // by lag) for plots.
  std::vector<SignalEvidence> pooled;
  std::vector<double> lags_s;
  std::map<std::string, std::vector<double>> cross_correlation;
  double rms_deg = 0.0;
  double effective_samples = 0.0;

  const SignalEvidence* Pooled(const std::string& signal) const;
};

// Diagnoses the residual of simulated angles [rad] (one matrix per
// experiment, laid out as Experiment::measured and passed through
// Experiment::AsMeasured) against the experiments' measured angles, or of
// the simulated tracked points [m] against the measured ones. The RMS
// figures of an experiment and of the whole are over its channels, deg or
// mm: the loop never mixes experiments of angles and of tracked points.
ResidualDiagnostics DiagnoseResidual(const std::vector<Experiment>& experiments,
                                     const std::vector<Eigen::MatrixXd>& simulated_rad);

// The phases of an experiment from its inputs: still where every cable's
// input rate is below 2 % of the largest over the experiment, for at least
// 0.3 s; moving otherwise.
std::vector<ProtocolPhase> ProtocolPhases(const Experiment& experiment);

nlohmann::json ToJson(const ResidualDiagnostics& diagnostics);

}  // namespace ccsrm::identify
