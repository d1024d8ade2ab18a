#pragma once
// Identification (SPEC 6): the friction, damping and pre-tension that make
// the simulated joint angles match the measured ones over one or several
// experiments, by Ceres' Levenberg-Marquardt, with standard errors,
// correlations and an identifiability check.
//
// The problem. Parameters by name (sim::Parameters(): mu, mu_s, ...), each
// free or fixed. Residuals: (simulated - measured) / noise, per measured
// frame, joint and axis, in degrees over degrees. The free parameters are
// optimised in a scaled space, u = p / s, with s the magnitude of the start
// value (else of the nominal value, else 1 % of the bounds' width), so every
// unknown is of order 1. Bounds go to Ceres as bounds on u, so every trial
// point of the trust region lies inside them.
//
// Derivatives. By finite differences over deterministic simulations, at the
// relative step that issue 10 checked (1e-2: derivatives at 1e-2 and 3e-3
// agree within 5 % at the default solver settings; docs/model-notes.md).
// The Jacobian at the final point is second order: central where both trial
// points fit inside the bounds, else one-sided away from the bound (the
// plans of sensitivity.h). The Jacobians that only steer the descent are
// first-order forward differences, unless central_differences_throughout.
// Every finite-difference point lies inside the bounds: Ceres' own numeric
// differentiation does not know the bounds, so this evaluator does it. The
// runs of one Jacobian (1 or 2 per free parameter and experiment) go to the
// backend as one batch.
//
// Uncertainty. ceres::Covariance (dense SVD, exact null directions dropped)
// of the weighted residuals' Jacobian, times the residual variance
// 2 cost / (N - p), times N / N_eff: mocap residuals are autocorrelated (a
// 1 Hz filter on 100 Hz frames), so N samples carry the information of about
// N_eff independent ones. N_eff sums, over every residual series
// (experiment, joint, axis), its length over its integrated autocorrelation
// time (Geyer's initial positive sequence). 95 % intervals use Student's t
// with N_eff - p degrees of freedom.
//
// Identifiability. Singular values of the Jacobian in the scaled space. A
// direction v_k with singular value σ_k moves the scaled parameters by a
// standard error of σ_res / σ_k (σ_res² the variance factor above). A
// parameter is identifiable when its standard error in this space, the
// root of Σ_k v_ik² (σ_res / σ_k)², is below max_relative_standard_error of
// its estimate (at least a tenth of its scale s); otherwise it gets no standard error and no
// interval, and the directions that make it so are named as combinations.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/identify/adequacy.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/runs.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {

// The nine parameters of SPEC 6, in its order.
std::vector<std::string> Spec6ParameterNames();

// Reported after every iteration of the minimiser (iteration 0 is the start).
struct IterationProgress {
  int iteration = 0;
  double cost = 0.0;               // 1/2 Σ r², r in units of the noise
  double rms_deg = 0.0;            // of the angles; NaN without measured angles
  double rms_mm = 0.0;             // tracked points' Euclidean RMS error; NaN without any
  double relative_decrease = 0.0;  // of the cost, this iteration (0 at the start)
  double trust_region_radius = 0.0;
  bool step_accepted = true;
  std::int64_t simulations = 0;  // so far
  double wall_time_s = 0.0;
  std::vector<std::pair<std::string, double>> values;  // the free parameters
};

// The state of a fit after an accepted iteration (and at its start): what
// resuming it needs (ccsrm identify --resume; docs/cluster.md). Levenberg-
// Marquardt after an accepted step holds only the point, the trust region
// radius and the damping floor (Ceres resets its decrease factor on every
// accepted step), so a fit resumed from here takes the same steps as one
// never stopped.
struct FitCheckpoint {
  int iterations = 0;                // minimiser iterations done, accepted and not
  std::vector<double> u;             // the free parameters in the scaled space, p / scale
  std::vector<double> values;        // the same as values (for people; u is what is used)
  double trust_region_radius = 0.0;  // Ceres' radius for the next step
  double min_lm_diagonal = 0.0;      // the damping floor set at the start (0: Ceres' own)
  bool jacobi_scaling = true;        // Ceres' Jacobi scaling (off with the floor)
  std::int64_t simulations = 0;      // run so far
  std::vector<double> cost_history;  // per accepted iteration, from the start
  // The runs at the start values, per experiment, as Evaluation keeps them
  // (the report's start errors), so that resuming does not run them again.
  std::vector<Eigen::MatrixXd> start_angles_rad;
};

struct IdentificationOptions {
  // The parameters to fit, by name. Default: SPEC 6's nine (mu, mu_s, mu_c,
  // mu_c_s, beta, c_sc, c_lc, T_p, T_d0). Each Jacobian then costs 18 runs
  // per experiment; fewer free parameters cost proportionally less.
  std::vector<std::string> free_parameters = Spec6ParameterNames();
  // Values set over every experiment's nominal configuration before the fit
  // (`--params`, `--set`): the start value of a free parameter, the value of
  // a fixed one. Default: none (the nominal values).
  std::map<std::string, double> values;
  // Narrower bounds for free parameters, name -> (lower, upper). Each must
  // lie inside the parameter's own bounds (sim::Parameters()) and contain
  // the start value. Default: the parameter's own bounds.
  std::map<std::string, std::pair<double, double>> bounds;
  // The scale s of a free parameter in the scaled space u = p / s, name ->
  // s > 0. Default: the magnitude of its start value, else of its nominal
  // value, else 1 % of its bounds' width. Give one where the start is 0 or
  // tiny but the parameter's natural size is known (an effect's realistic
  // magnitude): the finite-difference step is relative_step s.
  std::map<std::string, double> scales;
  // Relative finite-difference step: a parameter p moves by r s. Default
  // 1e-2 (see above).
  double relative_step = 1e-2;
  // At the final point, also differentiate at relative_step / 3 and compare
  // (ParameterEstimate::derivative_step_disagreement): where the angles
  // jump with a parameter (a breakaway that happens or not, a stick-slip
  // cycle that gains or loses a slip), its derivative depends on the step
  // and the fit's interval for it means nothing; the report says so. Costs
  // two runs per free parameter and experiment. Default true.
  bool check_derivative_steps = true;
  // Central differences in every Jacobian, also those that only steer the
  // steps. Default false: while the fit descends, Jacobians are first-order
  // forward differences (trial p + h, or p - h against the upper bound): one
  // run per free parameter and experiment instead of two. Their O(h) error
  // (about 1 % at r = 1e-2) only bends a step, which the next Jacobian
  // corrects. The Jacobian at the final point, from which the standard
  // errors, intervals and identifiability come, is always second-order
  // (central, reusing the last forward runs at p + h).
  bool central_differences_throughout = false;
  // Simulations at a time on this machine (ThreadBackend). Default: every core.
  int threads = DefaultThreads();
  // Another backend (null: threads on this machine).
  std::shared_ptr<SimulationBackend> backend;
  // Levenberg-Marquardt stopping rules (ceres::Solver::Options of the same
  // names). Default 30 iterations; a relative cost decrease below 1e-6, a
  // relative step below 1e-6 or a gradient below 1e-10 stops the fit as
  // converged.
  int max_iterations = 30;
  double function_tolerance = 1e-6;
  double parameter_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  // Ceres' initial trust region radius (Levenberg-Marquardt: the inverse of
  // the first damping, relative to the Jacobian's diagonal). Default 1: the
  // first step goes about halfway to the Gauss-Newton point. Ceres' own
  // default (1e4) takes the whole step at once, which on a stick-slip arm can
  // jump from a smooth region of the cost into a rough one (where static
  // friction exceeds kinetic) and stall there.
  double initial_trust_region_radius = 1.0;
  // Levenberg-Marquardt damps each free parameter in proportion to its own
  // curvature (the squared norm of its column of the scaled Jacobian:
  // Marquardt's scaling), so a parameter the data barely feel is barely
  // damped and can take a step of many times its size on a gradient that
  // is mostly noise or nonlinearity. Each parameter is damped at least as
  // if its curvature were this fraction of the largest one at the start
  // (ceres::Solver::Options::min_lm_diagonal, Jacobi scaling off, which is
  // the same scaling above the floor). Default 0.01. 0: Marquardt's alone.
  double min_relative_damping = 0.01;
  // The fit also stops, as converged, once an accepted step moved every free
  // parameter by less than this fraction of its standard error (as reported,
  // autocorrelation included): further
  // steps would change the estimate by amounts the data cannot tell apart
  // (and each costs a Jacobian). Default 0.1. 0 turns the rule off.
  double converged_step_fraction = 0.1;
  // And once an accepted step lowered the effective chi-square,
  // 2 cost N_eff / N, by less than this many times the residual variance
  // 2 cost / (N - p) (at least 1): a difference the data cannot tell apart.
  // At the noise floor the variance is 1; where the model misses something
  // the residuals, and the chance differences of the cost, are that much
  // larger. Default 1. 0 turns the rule off.
  double min_effective_chi2_decrease = 1.0;
  // A parameter whose standard error exceeds this fraction of its scale is
  // reported as not identifiable. Default 0.25: its 95 % interval would
  // then span about ±50 % of the value, which says only its order of
  // magnitude.
  double max_relative_standard_error = 0.25;
  // Called after every iteration and after every simulation; may be empty.
  std::function<void(const IterationProgress&)> on_iteration;
  RunFinishedCallback on_run;
  // Called at the start and after every accepted iteration with the fit's
  // state (to be saved: ccsrm identify writes it atomically); may be empty.
  std::function<void(const FitCheckpoint&)> on_checkpoint;
  // Continue from a saved state of the same fit (same experiments and
  // options) instead of the start values. Null (the default): from the start.
  std::shared_ptr<const FitCheckpoint> resume;

  // False with the reason naming the field: an unknown or repeated
  // parameter name, no free parameter, bounds for a parameter that is not
  // free, bounds outside the parameter's own or not increasing, a value out
  // of bounds, relative_step outside (0, 0.1], threads < 1,
  // max_iterations < 0, tolerances <= 0, max_relative_standard_error <= 0,
  // converged_step_fraction < 0, min_effective_chi2_decrease < 0,
  // min_relative_damping outside [0, 1], a scale
  // for a parameter that is not free or not positive.
  bool IsValid(std::string* error) const;
};

enum class IdentificationTermination {
  kConverged,      // a stopping tolerance was met
  kNoConvergence,  // max_iterations reached first
  kFailed,         // the minimiser could not go on (e.g. the start point diverges)
};
const char* TerminationName(IdentificationTermination termination);

struct ParameterEstimate {
  std::string name;
  std::string units;
  bool free = false;
  double start = 0.0;               // free: start value; fixed: the value used
  double value = 0.0;               // the estimate (fixed: the value used)
  double lower = 0.0, upper = 0.0;  // bounds of the fit
  double scale = 0.0;               // s of the scaled space
  bool identifiable = true;         // false: no std_error or interval (NaN), see unidentifiable
  double std_error = std::numeric_limits<double>::quiet_NaN();
  double ci95_lower = std::numeric_limits<double>::quiet_NaN();
  double ci95_upper = std::numeric_limits<double>::quiet_NaN();
  bool at_bound = false;  // the estimate sits on a bound: its interval is not symmetric
  // Free: ||J_s - J_s/3|| / max(||J_s||, ||J_s/3||) of its column of the
  // weighted residuals' Jacobian at the final point, at the relative step s
  // of derivative_step and s/3 (IdentificationOptions::check_derivative_steps);
  // above kDerivativeStepLimit the angles are not smooth in it there. NaN
  // when not checked (or a measurement parameter, exact at any step).
  double derivative_step_disagreement = std::numeric_limits<double>::quiet_NaN();
  // The relative step of its column in the singular values and intervals:
  // the fit's r, or r/3 where r and r/3 disagree and r/3 and r/9 agree (a
  // derivative that bends between r/3 and r). NaN when not checked.
  double derivative_step = std::numeric_limits<double>::quiet_NaN();
};

// Derivatives at two steps that differ by more than this are not a
// derivative: the bound issue 10 set for `ccsrm derivatives` (second-order
// differences at 1e-2 and 3e-3 of a smooth response agree within a few
// tenths of a per cent).
inline constexpr double kDerivativeStepLimit = 0.05;

// A direction of the scaled parameters that the data do not pin down: one
// that alone gives some parameter more than max_relative_standard_error, or
// the largest contributor to the error of an undetermined parameter that no
// such direction holds (its error spread over several directions).
struct UnidentifiableDirection {
  double singular_value = 0.0;
  // The largest standard error the direction gives a parameter, relative to
  // its estimate as in the parameters' test (inf for σ_k = 0); below the
  // threshold for a direction of the second kind.
  double relative_std_error = 0.0;
  // The parameters that make up the direction, largest share first, with
  // their component in the (unit) singular vector.
  std::vector<std::pair<std::string, double>> components;
  std::string Describe() const;  // e.g. "0.71 T_p - 0.70 mu_c"
};

// Errors of one joint angle series: one experiment, or all of them.
//
// Fit percent, 100 (1 - |sim - meas| / |meas - mean of each series|),
// compares the error with the axis's own motion, so it means something
// only on an axis the arm is driven about. On one that barely moves (θy of
// a joint bent in its plane) the ratio measures noise and by-products, and
// a fit good to hundredths of a degree can score -12 %. It is defined
// (finite) only where the axis's motion, the RMS of its measured angles
// about each series' mean, is at least kFitMotionShare of the joint's
// larger axis motion and kFitMotionNoiseRatio times its measurement noise;
// elsewhere it is NaN, and the RMS error is to be read against
// motion_rms_deg.
struct ChannelErrors {
  // [joint][axis], axis 0 θx, 1 θy, over the measured frames.
  std::vector<std::array<double, 2>> rms_deg;
  std::vector<std::array<double, 2>> fit_percent;  // NaN: the axis barely moves
  std::vector<std::array<double, 2>> motion_rms_deg;
  std::vector<std::array<std::size_t, 2>> samples;
  double rms_deg_overall = 0.0;
  // Fit percent over every series whose axis has one defined.
  double fit_percent_overall = 0.0;
};

// An axis moving less than this share of its joint's larger axis motion is
// a by-product of the motion, not a motion the arm is driven through.
inline constexpr double kFitMotionShare = 0.1;
// An axis moving less than this many standard deviations of its
// measurement noise is not told apart from the noise.
inline constexpr double kFitMotionNoiseRatio = 3.0;

// The errors of simulated angles [rad] (one matrix per experiment, laid out
// as Experiment::measured) against the experiments' measured angles,
// every experiment together (the noise of a joint: its experiments' mean
// Experiment::noise_deg).
ChannelErrors AngleErrors(const std::vector<const Experiment*>& experiments,
                          const std::vector<const Eigen::MatrixXd*>& simulated);

struct ExperimentFit {
  std::string name;
  std::string path;
  bool angles_from_pipeline = false;
  std::vector<double> noise_deg;
  std::string noise_source;
  ChannelErrors start;  // at the start values
  ChannelErrors fitted;
  // The final run: summary, and the trajectory at the experiment's sample times.
  sim::SimulationResult run;
  sim::ArmParameters parameters;  // the parameters of that run
  Eigen::MatrixXd simulated;      // as Experiment::measured
  // Of an experiment of tracked points: their errors at the start values and
  // at the fitted ones, and the capture frame's placement at the fitted
  // ones (the identity for points recorded in W).
  std::vector<TrackedPoint> points;
  TrackedPointErrors start_points;
  TrackedPointErrors fitted_points;
  bool placed_in_capture_frame = false;
  RigidPlacement placement;
};

struct IdentificationSummary {
  IdentificationTermination termination = IdentificationTermination::kFailed;
  bool converged() const { return termination == IdentificationTermination::kConverged; }
  std::string message;  // Ceres' reason, or why the fit stopped
  int iterations = 0;   // minimiser iterations (successful and not)
  std::int64_t simulations = 0;
  int threads = 0;
  double wall_time_s = 0.0;
  double relative_step = 0.0;
  bool central_differences_throughout = false;
  std::vector<double> cost_history;  // per iteration, from the start
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::size_t residuals = 0;                  // N
  double effective_samples = 0.0;             // N_eff
  double residual_variance = 0.0;             // 2 cost / (N - p): 1 at the noise floor
  std::vector<ParameterEstimate> parameters;  // free ones first, in the options' order
  std::vector<std::string> free_names;
  Eigen::MatrixXd correlation;          // free × free; NaN rows of unidentifiable parameters
  std::vector<double> singular_values;  // scaled Jacobian, descending
  // At the final point: the weighted residuals (simulated - measured) /
  // noise, and their Jacobian with respect to the scaled free parameters
  // u = p / scale (columns in free_names' order). Rows: experiment by
  // experiment, frame by frame, columns 2 joint + axis, measured entries
  // only. Empty when the final point did not run.
  Eigen::VectorXd weighted_residuals;
  Eigen::MatrixXd jacobian;
  std::vector<UnidentifiableDirection> unidentifiable;
  ChannelErrors start_errors;  // every experiment together
  ChannelErrors errors;
  std::vector<ExperimentFit> experiments;
  bool covariance_available = false;
  std::string covariance_message;  // why not, when not
  // Whether the fitted model explains the data (adequacy.h): the residual of
  // the final point against each joint axis's measured noise. Reported
  // first; not assessed when the final run did not complete.
  ModelAdequacy adequacy;

  const ParameterEstimate* Find(const std::string& name) const;
  // The 95 % interval of `p` widened by adequacy.misfit_scale() about the
  // estimate (the interval itself when the model is adequate).
  std::array<double, 2> MisfitInterval(const ParameterEstimate& p) const;
  // One line; and the whole result as a table.
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Fits the free parameters to every experiment at once. Throws InputError
// for invalid options or experiments before any simulation runs (also when a
// value makes an experiment's parameters invalid). A fit that fails or does
// not converge is returned with its termination, not thrown.
IdentificationSummary Identify(const std::vector<Experiment>& experiments,
                               const IdentificationOptions& options);

// Reads a parameter file (`ccsrm identify --params`) into options. Each
// entry is `name: value` (a start value, or the value of a fixed parameter)
// or `name: {value: v, free: true|false, bounds: [lower, upper]}`; a truth
// file's `parameters:` section is read as values. Checked whole before
// anything changes. Throws InputError "<file>: line N, key 'x': ..." for an
// unknown name or field, a value that is not a number or out of bounds.
void ApplyParameterFile(const std::string& yaml_text, const std::string& file,
                        IdentificationOptions* options);

// The fit's parameter options as `ccsrm identify` and `ccsrm loop` take
// them, applied in this order: the free list (when `free` is not null; each
// name checked), a parameter file (when `params_path` is not empty:
// ApplyParameterFile), then values by name (start values of free
// parameters; `--set name=value`). Errors name the options --free, --params'
// file and --set, as every door that takes them (the commands, the Python
// module). Throws InputError.
void ApplyFitParameters(const std::vector<std::string>* free, const std::string& params_path,
                        const std::vector<std::pair<std::string, double>>& values,
                        IdentificationOptions* options);

// fit.json: every number of the summary, SPEC 6 names.
nlohmann::json ToJson(const IdentificationSummary& summary);

// A checkpoint's state as JSON (numbers round-trip to the bit; an unmeasured
// angle, NaN, as null), and back. FromJson throws InputError naming `file`
// and the field for a state it cannot read.
nlohmann::json ToJson(const FitCheckpoint& checkpoint);
FitCheckpoint FitCheckpointFromJson(const nlohmann::json& json, const std::string& file);

// Writes a fit directory (created if missing, files replaced atomically):
// fit.json; per experiment <name>.fit.h5 (ccsrm-run/1 of the final run at
// the measured frames) and <name>.angles.csv (time, then measured, fitted
// and residual θx, θy of every joint, in degrees). Returns the paths written.
std::vector<std::string> WriteFitDirectory(const IdentificationSummary& summary,
                                           const std::vector<Experiment>& experiments,
                                           const std::string& directory);

}  // namespace ccsrm::identify
